#include "core/file_kind.hpp"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <iterator>

namespace spx {

std::string lower_extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

FileKind file_kind(const std::string& path, const std::string& head) {
  if (head.compare(0, 4, "\x89SPX") == 0) return FileKind::spx;
  if (head.compare(0, 4, " BDV") == 0) return FileKind::vdb;
  if (head.compare(0, 4, "glTF") == 0) return FileKind::glb;
  const size_t first = head.find_first_not_of(" \t\r\n");
  if (first != std::string::npos && (head[first] == '{' || head[first] == '[')) return FileKind::json;
  const char* meshes[] = {".obj", ".ply", ".stl", ".off", ".fbx", ".dae"};
  if (std::find(std::begin(meshes), std::end(meshes), lower_extension(path)) != std::end(meshes)) return FileKind::mesh;
  if (head.find('\0') != std::string::npos) return FileKind::binary;
  return FileKind::unknown;
}

std::string describe(FileKind kind) {
  switch (kind) {
    case FileKind::spx: return "a runtime .spx file (from proxy-export)";
    case FileKind::vdb: return "an OpenVDB file (from sdf-build)";
    case FileKind::glb: return "a binary glTF file";
    case FileKind::json: return "a JSON file";
    case FileKind::mesh: return "a mesh";
    case FileKind::binary: return "a binary file";
    case FileKind::unknown: break;
  }
  return "a file of no kind the tools know";
}

}  // namespace spx
