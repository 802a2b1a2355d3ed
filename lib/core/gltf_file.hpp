#pragma once
// A glTF asset as its JSON document and one binary buffer, to add nodes and extensions to and
// write back as GLB with everything else it holds (meshes, skins, clips) untouched.
#include <string>

#include "core/json_io.hpp"

namespace spx {

struct GltfFile {
  json doc;         // the document; when `bin` is not empty, buffers[0] is it
  std::string bin;  // the binary buffer (a GLB's BIN chunk, or the file's buffers merged)
  size_t decoded_views = 0;  // views EXT_meshopt_compression compressed in the file, decoded here
};

// Reads a .glb, or a .gltf whose buffers are data: URIs or files beside it (merged into one, the
// views moved with them; a GLB's too where it has more than its BIN chunk). Views compressed by
// EXT_meshopt_compression come out decoded (core/gltf_meshopt), so the file reads as the plain
// one it stands for. Exit 2 naming the file when it is not a glTF 2.0 asset; exit 3 for what it
// holds that this cannot carry (a buffer that cannot be read).
GltfFile read_gltf_file(const std::string& path);

// The same, from the file's bytes (a .gltf's buffer files are still looked for beside `path`).
GltfFile gltf_from_bytes(const std::string& bytes, const std::string& path);

// A member that is a count, an index or an offset: `otherwise` where it is missing, else a whole
// number 0 or above (unsigned as read from a file, or signed where code set it), else exit 2
// naming `path`: "not a glTF 2.0 asset: <of>'s '<key>' is not a whole number 0 or above (<value>)".
size_t gltf_whole_number(const json& object, const char* key, size_t otherwise, const std::string& path, const char* of);

// `object`'s extension `name` (object.extensions.<name>), or null where it has none.
const json* extension_of(const json& object, const char* name);
// Removes `object`'s extension `name`, and its extensions object where that leaves it empty.
void remove_extension_of(json& object, const char* name);

// Takes `name` out of the document's extensionsUsed and extensionsRequired (a list it leaves empty
// goes too): what a mend does once nothing in the file carries the extension any more.
void drop_extension(json& doc, const std::string& name);

// The GLB container: the JSON chunk, then the BIN chunk when `bin` is not empty.
std::string encode_glb(const GltfFile& file);

}  // namespace spx
