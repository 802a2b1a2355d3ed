// libFuzzer target: the glTF container reader (GLB chunks, a .gltf's JSON and its data: buffers,
// views compressed by EXT_meshopt_compression decoded) on arbitrary bytes, then what is done to it
// before assimp reads it (the extensions it requires, the spec's rules on skins, the node tree and
// clips, its instanced meshes made nodes, its skins given identity matrices, its integer accessors
// rewritten as floats, its mirrored nodes' channels completed, its STEP keys held, its cubic
// splines made linear). Bad input must end in spx::Error, never a crash or another exception;
// what it lets through is an object whose views all point into its one buffer, whose rewritten
// accessors are floats in views inside it, and whose skins each have a matrix per joint.
#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "core/gltf_file.hpp"
#include "mesh/gltf_accessors.hpp"
#include "mesh/gltf_check.hpp"
#include "mesh/gltf_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  try {
    const spx::GltfFile file = spx::gltf_from_bytes(bytes, "fuzz-dir-that-is-not-there/fuzz.gltf");
    if (!file.doc.is_object() || !file.doc["bufferViews"].is_array()) std::abort();
    const bool glb = bytes.compare(0, 4, "glTF") == 0;
    for (const auto& view : file.doc["bufferViews"]) {
      if (!glb && view["buffer"] != 0) std::abort();  // a .gltf's buffers merged into one
      if (spx::extension_of(view, "EXT_meshopt_compression")) std::abort();  // every compressed view decoded
    }
    spx::encode_glb(file);
    spx::check_required_extensions(file.doc, "fuzz.gltf");
    spx::check_gltf_rules(file, "fuzz.gltf");
    spx::GltfFile floats = file;
    const size_t nodes = floats.doc.contains("nodes") && floats.doc["nodes"].is_array() ? floats.doc["nodes"].size() : 0;
    if (spx::instances_as_nodes(floats, "fuzz.gltf") > 0 && floats.doc["nodes"].size() < nodes) std::abort();
    spx::skins_given_bind_matrices(floats);
    for (const auto& skin : floats.doc.value("skins", spx::json::array())) {  // every skin's matrices given, one per joint
      const auto& matrices = floats.doc["accessors"][skin["inverseBindMatrices"].get<size_t>()];
      if (matrices["type"] != "MAT4" || matrices["count"].get<size_t>() < skin["joints"].size()) std::abort();
    }
    std::vector<std::vector<std::string>> passed_over;
    const size_t pointed = spx::channels_as_assimp_reads(floats, passed_over);
    for (size_t a = 0; a < passed_over.size(); ++a) {  // every channel left moves a node
      const spx::json& clip = floats.doc["animations"][a];
      if (clip.is_object() && clip.contains("channels") && clip["channels"].is_array())
        for (const auto& channel : clip["channels"])
          if (spx::detail::channel_target(channel).node == SIZE_MAX || !channel["target"].contains("node")) std::abort();
    }
    const size_t views = floats.doc["bufferViews"].size();
    const size_t changed = spx::float_accessors(floats, "fuzz.gltf");
    if (floats.doc["bufferViews"].size() != views + changed) std::abort();
    for (size_t v = views; v < views + changed; ++v) {  // the views it added, the only ones it trusts
      const auto& view = floats.doc["bufferViews"][v];
      if (view["byteOffset"].get<size_t>() + view["byteLength"].get<size_t>() > floats.bin.size()) std::abort();
    }
    const size_t channels = spx::complete_mirrored_channels(floats, "fuzz.gltf");
    const size_t steps = spx::step_samplers_as_held_keys(floats, "fuzz.gltf");
    std::vector<spx::AddedKeys> added;
    const size_t cubic = spx::cubic_samplers_as_keys(floats, "fuzz.gltf", added);
    if (cubic > 0 && added.size() != floats.doc["animations"].size()) std::abort();
    if (pointed + changed + channels + steps + cubic > 0) spx::encode_glb(floats);
  } catch (const spx::Error&) {
  }
  return 0;
}
