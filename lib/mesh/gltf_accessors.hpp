#pragma once
// A glTF's accessors read and written as a reader takes them: what the mends of mesh/gltf_input
// (the file's data) and mesh/gltf_clips (its clips) share. Internal to mesh/.
#include <cstdint>
#include <string>
#include <vector>

#include "core/gltf_file.hpp"

namespace spx::detail {

inline constexpr int kFloat = 5126;

// Members read without trusting their types (a file's wrong type is its fault, not an internal error).
bool flag(const json& object, const char* key);
std::string text(const json& object, const char* key);
// An index: a whole number 0 or above (signed where the code set it, unsigned as read).
bool is_index(const json& v);

// Components per element of the types an attribute or a clip's output may have; 0 for the others.
size_t components(const json& accessor);

// The accessor's values as a reader takes them, dense (zeros where it has no view; sparse ones
// put in place). Exit 2 naming `path` where the accessor or its view is out of range.
std::vector<double> accessor_values(const GltfFile& file, const json& accessor, const std::string& path);

// What a clip's channel moves: its target's node and path, or those its KHR_animation_pointer
// names ("/nodes/3/rotation": node 3, "rotation"; "/meshes/1/weights": mesh 1's weights, which
// every node placing it without weights of its own takes; `pointer` holds it). `node` and `mesh`
// are SIZE_MAX where it names neither (none given, or another object's property:
// "/materials/0/emissiveFactor"), and `path` empty where it names no path of the four a channel
// may move a node by.
struct ChannelTarget {
  size_t node = SIZE_MAX, mesh = SIZE_MAX;
  std::string path, pointer;
};
ChannelTarget channel_target(const json& channel);

// Appends `values` as a float accessor of `type` (an attribute's, a clip's, or MAT4) in a view of
// its own (with min and max where it is a SCALAR, as a clip's times must have); returns its index.
size_t add_float_accessor(GltfFile& file, const std::vector<double>& values, const std::string& type);

}  // namespace spx::detail
