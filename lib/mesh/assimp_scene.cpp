#include "mesh/assimp_scene.hpp"

#include <optional>

#include "core/error.hpp"
#include "core/file_kind.hpp"
#include "core/gltf_file.hpp"
#include "mesh/gltf_input.hpp"

namespace spx {

const aiScene* read_scene(Assimp::Importer& importer, const std::string& path, unsigned flags, const std::string& what) {
  const std::string ext = lower_extension(path);
  const bool gltf = ext == ".gltf" || ext == ".glb";
  if (gltf) {
    std::optional<GltfFile> file;
    try {
      file = read_gltf_file(path);
    } catch (const Error&) {
      // assimp's turn: where it fails too, the error below says what is wrong with the file.
    }
    if (file) {
      check_required_extensions(file->doc, path);
      if (float_accessors(*file, path) > 0) {
        const std::string glb = encode_glb(*file);
        const aiScene* scene = importer.ReadFileFromMemory(glb.data(), glb.size(), flags, "glb");
        if (scene && scene->mRootNode) return scene;
        fail_input(path, "cannot read " + what + ": " + importer.GetErrorString());
      }
    }
  }
  const aiScene* scene = importer.ReadFile(path, flags);
  if (scene && scene->mRootNode) return scene;
  const std::string error = importer.GetErrorString();
  if (gltf) {
    const GltfFile file = read_gltf_file(path);  // throws saying what is wrong with the container
    if (file.doc.value("meshes", json::array()).empty()) fail_input(path, "contains no mesh");
    if (ext == ".gltf") {
      const std::string glb = encode_glb(file);
      scene = importer.ReadFileFromMemory(glb.data(), glb.size(), flags, "glb");
      if (scene && scene->mRootNode) return scene;
    }
  }
  fail_input(path, "cannot read " + what + ": " + error);
}

}  // namespace spx
