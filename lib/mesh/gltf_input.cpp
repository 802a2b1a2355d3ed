#include "mesh/gltf_input.hpp"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <map>
#include <set>
#include <vector>

#include "core/error.hpp"
#include "mesh/gltf_accessors.hpp"

namespace spx {
// The accessor helpers mesh/gltf_accessors.hpp declares, shared with the clips' mends.
namespace detail {

bool flag(const json& object, const char* key) {
  const auto it = object.find(key);
  return it != object.end() && it->is_boolean() && it->get<bool>();
}

std::string text(const json& object, const char* key) {
  const auto it = object.find(key);
  return it != object.end() && it->is_string() ? it->get<std::string>() : "";
}

bool is_index(const json& v) { return v.is_number_integer() && v.get<int64_t>() >= 0; }

size_t components(const json& accessor) {
  const std::string type = text(accessor, "type");
  if (type == "SCALAR") return 1;
  if (type == "VEC2") return 2;
  if (type == "VEC3") return 3;
  if (type == "VEC4") return 4;
  return 0;
}

}  // namespace detail

using namespace detail;

namespace {

constexpr const char* kInstancing = "EXT_mesh_gpu_instancing";

bool changes_no_geometry(const std::string& extension) {
  for (const char* prefix : {"KHR_materials_", "KHR_texture_", "EXT_texture_", "KHR_lights_"})
    if (extension.rfind(prefix, 0) == 0) return true;
  return false;
}

size_t component_bytes(int type) {
  switch (type) {
    case 5120:
    case 5121:
      return 1;
    case 5122:
    case 5123:
      return 2;
    case 5125:
    case kFloat:
      return 4;
    default:
      return 0;
  }
}

template <typename T>
double stored(const char* at) {
  T c;
  std::memcpy(&c, at, sizeof c);  // glTF is little-endian, as this machine
  return double(c);
}

// A normalized component's value by the spec (min and max are given in the same integers).
double normalized_value(double c, int type) {
  switch (type) {
    case 5120:
      return std::max(c / 127.0, -1.0);
    case 5121:
      return c / 255.0;
    case 5122:
      return std::max(c / 32767.0, -1.0);
    case 5123:
      return c / 65535.0;
    default:
      return c;
  }
}

// One component at `at` as a reader takes it.
double component_value(const char* at, int type, bool normalized) {
  double c = 0;
  switch (type) {
    case 5120:
      c = stored<int8_t>(at);
      break;
    case 5121:
      c = stored<uint8_t>(at);
      break;
    case 5122:
      c = stored<int16_t>(at);
      break;
    case 5123:
      c = stored<uint16_t>(at);
      break;
    case 5125:
      c = stored<uint32_t>(at);
      break;
    default:
      c = stored<float>(at);
  }
  return normalized ? normalized_value(c, type) : c;
}

// The bytes [offset, offset + length) of view `v` in the binary buffer, checked.
struct ViewBytes {
  size_t begin = 0, end = 0, stride = 0;
};

ViewBytes view_bytes(const GltfFile& file, size_t v, const std::string& path) {
  const json& views = file.doc["bufferViews"];
  if (v >= views.size()) fail_input(path, "an accessor names a bufferView that does not exist (" + std::to_string(v) + ")");
  const json& view = views[v];
  if (gltf_whole_number(view, "buffer", 0, path, "a bufferView") != 0)
    fail_unsupported(path, "an integer accessor lies in a buffer other than the file's own binary one");
  ViewBytes out;
  out.begin = gltf_whole_number(view, "byteOffset", 0, path, "a bufferView");
  out.end = out.begin + gltf_whole_number(view, "byteLength", 0, path, "a bufferView");
  out.stride = gltf_whole_number(view, "byteStride", 0, path, "a bufferView");
  if (out.end < out.begin || out.end > file.bin.size()) fail_input(path, "a bufferView runs past the end of its buffer");
  return out;
}

// Reads `count` elements of `n` components of `type` from view `v` at `offset` into `out`
// (element i's components at out[i * n]), or the elements listed in `at` where given.
void read_elements(const GltfFile& file, size_t v, size_t offset, size_t count, size_t n, int type, bool normalized,
                   std::vector<double>& out, const std::vector<size_t>* at, const std::string& path) {
  const ViewBytes view = view_bytes(file, v, path);
  const size_t element = n * component_bytes(type);
  const size_t stride = view.stride ? view.stride : element;
  if (count > 0 && (offset > view.end - view.begin || (count - 1) > (view.end - view.begin - offset) / stride ||
                    view.begin + offset + (count - 1) * stride + element > view.end))
    fail_input(path, "an accessor runs past the end of its bufferView");
  for (size_t i = 0; i < count; ++i) {
    const char* p = file.bin.data() + view.begin + offset + i * stride;
    const size_t to = at ? (*at)[i] : i;
    for (size_t c = 0; c < n; ++c) out[to * n + c] = component_value(p + c * component_bytes(type), type, normalized);
  }
}

// min or max as a reader takes them (given in the accessor's component type).
json float_bounds(const json& bounds, int type, bool normalized) {
  json out = json::array();
  for (const json& b : bounds) {
    if (!b.is_number()) return bounds;
    const double c = b.get<double>();
    out.push_back(double(float(normalized ? normalized_value(c, type) : c)));
  }
  return out;
}

// Appends `values` as floats in a view of their own; returns the view's index.
size_t append_float_view(GltfFile& file, const std::vector<double>& values) {
  while (file.bin.size() % 4) file.bin += '\0';
  file.doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", file.bin.size()}, {"byteLength", values.size() * 4}});
  for (double v : values) {
    const float f = float(v);
    file.bin.append(reinterpret_cast<const char*>(&f), 4);
  }
  return file.doc["bufferViews"].size() - 1;
}

// The accessors read as floating-point data (see the header), by index.
std::set<size_t> float_data_accessors(const json& doc, const std::string& path) {
  std::set<size_t> out;
  const auto add = [&](const json& index) {
    if (!is_index(index)) fail_input(path, "not a glTF 2.0 asset: an accessor index is not a whole number 0 or above");
    out.insert(size_t(index.get<int64_t>()));
  };
  // Each list held by name while it is walked (value() returns a copy; items() would outlive it).
  const json meshes = doc.value("meshes", json::array());
  for (const json& mesh : meshes) {
    const json primitives = mesh.is_object() ? mesh.value("primitives", json::array()) : json::array();
    for (const json& primitive : primitives) {
      if (!primitive.is_object()) continue;
      const json attributes = primitive.value("attributes", json::object());
      if (attributes.is_object())
        for (const auto& [name, index] : attributes.items())
          if (name.rfind("JOINTS_", 0) != 0 && name.rfind('_', 0) != 0) add(index);
      const json targets = primitive.value("targets", json::array());
      for (const json& target : targets)
        if (target.is_object())
          for (const auto& [name, index] : target.items()) add(index);
    }
  }
  const json clips = doc.value("animations", json::array());
  for (const json& clip : clips) {
    const json samplers = clip.is_object() ? clip.value("samplers", json::array()) : json::array();
    for (const json& sampler : samplers)
      if (sampler.is_object() && sampler.contains("output")) add(sampler["output"]);
  }
  return out;
}

}  // namespace

namespace detail {

std::vector<double> accessor_values(const GltfFile& file, const json& accessor, const std::string& path) {
  const size_t count = gltf_whole_number(accessor, "count", 0, path, "an accessor");
  const size_t n = components(accessor);
  const int type = accessor["componentType"].get<int>();
  const bool normalized = flag(accessor, "normalized");
  // An element takes a byte at least, or none where it is zero (no view): a count past both is no file's.
  if (count > std::max(file.bin.size(), size_t(1) << 20)) fail_input(path, "an accessor counts more elements than its file holds");
  std::vector<double> values(count * n, 0.0);
  if (accessor.contains("bufferView"))
    read_elements(file, gltf_whole_number(accessor, "bufferView", 0, path, "an accessor"),
                  gltf_whole_number(accessor, "byteOffset", 0, path, "an accessor"), count, n, type, normalized, values, nullptr,
                  path);
  if (accessor.contains("sparse")) {
    const json& sparse = accessor["sparse"];
    const auto as_spec_says = [&](bool ok) {
      if (!ok) fail_input(path, "not a glTF 2.0 asset: a sparse accessor is not as the spec says");
    };
    as_spec_says(sparse.is_object() && sparse.contains("indices") && sparse.contains("values") &&
                 sparse["indices"].is_object() && sparse["values"].is_object());
    const json& indices = sparse["indices"];
    const json& given = sparse["values"];
    const size_t k = gltf_whole_number(sparse, "count", 0, path, "a sparse accessor");
    const size_t index_type = gltf_whole_number(indices, "componentType", 0, path, "a sparse accessor's indices");
    as_spec_says(index_type == 5121 || index_type == 5123 || index_type == 5125);
    if (k > count) fail_input(path, "a sparse accessor replaces more elements than it has");
    std::vector<double> where(k);
    read_elements(file, gltf_whole_number(indices, "bufferView", 0, path, "a sparse accessor's indices"),
                  gltf_whole_number(indices, "byteOffset", 0, path, "a sparse accessor's indices"), k, 1, int(index_type), false,
                  where, nullptr, path);
    std::vector<size_t> at(k);
    for (size_t i = 0; i < k; ++i) {
      if (where[i] >= double(count)) fail_input(path, "a sparse accessor replaces an element it does not have");
      at[i] = size_t(where[i]);
    }
    read_elements(file, gltf_whole_number(given, "bufferView", 0, path, "a sparse accessor's values"),
                  gltf_whole_number(given, "byteOffset", 0, path, "a sparse accessor's values"), k, n, type, normalized, values,
                  &at, path);
  }
  return values;
}

size_t add_float_accessor(GltfFile& file, const std::vector<double>& values, const std::string& type) {
  json accessor = {{"bufferView", append_float_view(file, values)}, {"componentType", kFloat}, {"type", type}};
  accessor["count"] = values.size() / (type == "MAT4" ? 16 : components(accessor));
  if (type == "SCALAR" && !values.empty()) {
    accessor["min"] = json::array({double(float(*std::min_element(values.begin(), values.end())))});
    accessor["max"] = json::array({double(float(*std::max_element(values.begin(), values.end())))});
  }
  if (!file.doc.contains("accessors")) file.doc["accessors"] = json::array();
  file.doc["accessors"].push_back(accessor);
  return file.doc["accessors"].size() - 1;
}

}  // namespace detail

void check_required_extensions(const json& doc, const std::string& path) {
  const json required = doc.value("extensionsRequired", json::array());
  for (const json& e : required) {
    if (!e.is_string()) fail_input(path, "not a glTF 2.0 asset: its extensionsRequired lists a name that is not a string");
    const std::string name = e.get<std::string>();
    if (name == "KHR_draco_mesh_compression" || name == "KHR_mesh_quantization" || name == kInstancing ||
        name == "KHR_animation_pointer" || changes_no_geometry(name))
      continue;
    fail_unsupported(path, "requires the glTF extension " + name +
                               ", which the tools do not read (its meshes would come out missing or wrong); export it "
                               "without " + name);
  }
}

size_t float_accessors(GltfFile& file, const std::string& path) {
  json& doc = file.doc;
  if (!doc.contains("accessors")) return 0;
  json& accessors = doc["accessors"];
  if (!accessors.is_array()) fail_input(path, "not a glTF 2.0 asset: its 'accessors' is not a list");
  size_t changed = 0;
  for (size_t index : float_data_accessors(doc, path)) {
    if (index >= accessors.size()) fail_input(path, "a mesh or clip names an accessor that does not exist (" + std::to_string(index) + ")");
    json& accessor = accessors[index];
    if (!accessor.is_object() || !accessor.contains("componentType") || !accessor["componentType"].is_number_integer())
      fail_input(path, "not a glTF 2.0 asset: an accessor has no componentType");
    const int type = accessor["componentType"].get<int>();
    if (type == kFloat || component_bytes(type) == 0 || components(accessor) == 0) continue;
    const size_t view = append_float_view(file, accessor_values(file, accessor, path));
    const bool normalized = flag(accessor, "normalized");
    for (const char* bound : {"min", "max"})
      if (accessor.contains(bound) && accessor[bound].is_array()) accessor[bound] = float_bounds(accessor[bound], type, normalized);
    accessor["bufferView"] = view;
    accessor["componentType"] = kFloat;
    for (const char* gone : {"byteOffset", "normalized", "sparse"}) accessor.erase(gone);
    ++changed;
  }
  return changed;
}

namespace {

// An instance's translation, rotation or scale from the extension's accessor `name` (none where
// the attribute is not given); exit 2 naming `path` where it is not a list of `width` numbers
// for each of `count` instances.
std::vector<double> instance_values(const GltfFile& file, const json& attributes, const char* name, size_t width,
                                    size_t& count, const std::string& path) {
  if (!attributes.contains(name)) return {};
  const auto list = file.doc.find("accessors");
  if (list == file.doc.end() || !list->is_array()) fail_input(path, "not a glTF 2.0 asset: it has instances but no accessors");
  const json& accessors = *list;
  const json& index = attributes[name];
  if (!is_index(index) || size_t(index.get<int64_t>()) >= accessors.size() || !accessors[size_t(index.get<int64_t>())].is_object())
    fail_input(path, std::string("a node's EXT_mesh_gpu_instancing names no accessor for its ") + name);
  const json& accessor = accessors[size_t(index.get<int64_t>())];
  if (components(accessor) != width || !accessor.contains("componentType") || !accessor["componentType"].is_number_integer())
    fail_input(path, std::string("a node's EXT_mesh_gpu_instancing ") + name + " is not a list of " +
                         (width == 4 ? "VEC4" : "VEC3"));
  std::vector<double> values = accessor_values(file, accessor, path);
  const size_t n = values.size() / width;
  if (count != SIZE_MAX && n != count)
    fail_input(path, "a node's EXT_mesh_gpu_instancing attributes count different numbers of instances");
  count = n;
  return values;
}

}  // namespace

size_t instances_as_nodes(GltfFile& file, const std::string& path) {
  json& doc = file.doc;
  if (!doc.contains("nodes") || !doc["nodes"].is_array()) return 0;
  size_t expanded = 0;
  const size_t given = doc["nodes"].size();
  for (size_t n = 0; n < given; ++n) {
    const json node = doc["nodes"][n];  // a copy: nodes are added below
    if (!node.is_object() || !node.contains("mesh") || node.contains("skin") || !extension_of(node, kInstancing)) continue;
    const json& instancing = *extension_of(node, kInstancing);
    if (!instancing.is_object() || !instancing.contains("attributes") || !instancing["attributes"].is_object())
      fail_input(path, "a node's EXT_mesh_gpu_instancing has no attributes");
    const json& attributes = instancing["attributes"];
    size_t count = SIZE_MAX;
    const std::vector<double> t = instance_values(file, attributes, "TRANSLATION", 3, count, path);
    const std::vector<double> r = instance_values(file, attributes, "ROTATION", 4, count, path);
    const std::vector<double> s = instance_values(file, attributes, "SCALE", 3, count, path);
    if (count == SIZE_MAX) continue;  // no attribute: the node's mesh once, as it is
    json children = node.value("children", json::array());
    if (!children.is_array()) fail_input(path, "not a glTF 2.0 asset: a node's children are not a list");
    for (size_t i = 0; i < count; ++i) {
      json instance = {{"mesh", node["mesh"]}};
      if (node.contains("name") && node["name"].is_string())
        instance["name"] = node["name"].get<std::string>() + "#" + std::to_string(i + 1);
      const auto put = [&](const char* key, const std::vector<double>& v, size_t width) {
        if (!v.empty()) instance[key] = std::vector<double>(v.begin() + long(i * width), v.begin() + long((i + 1) * width));
      };
      put("translation", t, 3);
      put("rotation", r, 4);
      put("scale", s, 3);
      children.push_back(doc["nodes"].size());
      doc["nodes"].push_back(instance);
    }
    json& placed = doc["nodes"][n];
    placed.erase("mesh");
    placed["children"] = children;
    remove_extension_of(placed, kInstancing);
    ++expanded;
  }
  // Where no node has it any more, nor is it used or required.
  const bool left = std::any_of(doc["nodes"].begin(), doc["nodes"].end(),
                                [](const json& node) { return extension_of(node, kInstancing) != nullptr; });
  if (expanded > 0 && !left) drop_extension(doc, kInstancing);
  return expanded;
}

size_t meshes_split_by_node(GltfFile& file) {
  json& doc = file.doc;
  if (!doc.contains("nodes") || !doc["nodes"].is_array() || !doc.contains("meshes") || !doc["meshes"].is_array())
    return 0;
  json& meshes = doc["meshes"];
  const json given = meshes;  // copies are of the file's meshes, before any takes a node's weights
  // Per mesh, the mesh each node's way of drawing it (its skin, -1: none; its weights, "": the
  // mesh's) draws: the first met keeps the given one.
  std::vector<std::map<std::pair<int64_t, std::string>, size_t>> drawn(given.size());
  size_t changes = 0;
  for (json& node : doc["nodes"]) {
    if (!node.is_object() || !node.contains("mesh") || !is_index(node["mesh"])) continue;
    const size_t mesh = size_t(node["mesh"].get<int64_t>());
    if (mesh >= given.size() || !given[mesh].is_object()) continue;
    const int64_t skin = node.contains("skin") && is_index(node["skin"]) ? node["skin"].get<int64_t>() : -1;
    const bool weighed = node.contains("weights") && node["weights"].is_array();
    auto [it, first] = drawn[mesh].emplace(std::make_pair(skin, weighed ? node["weights"].dump() : ""), mesh);
    if (first && drawn[mesh].size() > 1) {
      it->second = meshes.size();
      meshes.push_back(given[mesh]);  // the same accessors, its own bones (or none) and weights
      ++changes;
    }
    node["mesh"] = it->second;
    if (weighed && meshes[it->second].value("weights", json()) != node["weights"]) {
      meshes[it->second]["weights"] = node["weights"];
      ++changes;
    }
  }
  return changes;
}

}  // namespace spx
