#pragma once
// glTF buffer views compressed by EXT_meshopt_compression (gltfpack -c and the web optimizers
// write them), decoded by meshoptimizer where the file is read (core/gltf_file), so that every
// reader of a GltfFile, and assimp after it, takes them as the plain data they stand for.
#include <optional>
#include <string>
#include <vector>

#include "core/json_io.hpp"

namespace spx {

inline constexpr const char* kMeshoptCompression = "EXT_meshopt_compression";

// A buffer's bytes, or none: a buffer without a uri (the extension's placeholder for the views'
// uncompressed data, which the file need not carry).
using BufferBytes = std::optional<std::string>;

// Decodes every buffer view of `doc` that EXT_meshopt_compression compresses, from the bytes of
// the buffer its extension names, mode by mode and then through its filter (octahedral,
// quaternion, exponential), into one buffer appended to `buffers` and to `doc`'s list; each such
// view then reads its data there, its extension gone, and the extension leaves extensionsUsed and
// extensionsRequired. Returns how many views were decoded (0: `doc` and `buffers` as they were).
// Exit 2 naming `path` where an extension breaks its rules (a count and stride that are not the
// view's length, a mode or filter it does not name, ...), where its bytes lie outside their buffer
// or hold less than the view, or where they do not decode; exit 3 for data of a codec version
// this meshoptimizer does not read.
size_t decode_meshopt_views(json& doc, std::vector<BufferBytes>& buffers, const std::string& path);

}  // namespace spx
