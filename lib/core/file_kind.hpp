#pragma once
// What a file is, for the tool it was handed to by mistake: the project's files and the ones
// around them told apart by their first bytes, meshes by their extension (they share no magic).
#include <string>

namespace spx {

// The file's extension with its dot, in lower case (".glb" for "Car.GLB"): what tools decide a
// format by.
std::string lower_extension(const std::string& path);

enum class FileKind { unknown, spx, vdb, glb, json, mesh, binary };

// From `head` (the file's first bytes; all of them to find a NUL anywhere) and `path`'s extension.
FileKind file_kind(const std::string& path, const std::string& head);

// "a runtime .spx file (from proxy-export)", "an OpenVDB file (from sdf-build)", "a mesh", ...
std::string describe(FileKind kind);

}  // namespace spx
