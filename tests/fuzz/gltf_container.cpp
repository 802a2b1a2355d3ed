// libFuzzer target: the glTF container reader (GLB chunks, a .gltf's JSON and its data: buffers)
// on arbitrary bytes. Bad input must end in spx::Error, never a crash or another exception; what
// it lets through is an object whose views all point into its one buffer.
#include <cstdint>
#include <cstdlib>
#include <string>

#include "core/error.hpp"
#include "core/gltf_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  try {
    const spx::GltfFile file = spx::gltf_from_bytes(bytes, "fuzz-dir-that-is-not-there/fuzz.gltf");
    if (!file.doc.is_object() || !file.doc["bufferViews"].is_array()) std::abort();
    const bool glb = bytes.compare(0, 4, "glTF") == 0;
    for (const auto& view : file.doc["bufferViews"])
      if (!glb && view["buffer"] != 0) std::abort();  // a .gltf's buffers merged into one
    spx::encode_glb(file);
  } catch (const spx::Error&) {
  }
  return 0;
}
