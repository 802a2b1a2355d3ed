// The mends of a glTF's clips, declared with the others in mesh/gltf_input.hpp.
#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "core/clip_steps.hpp"
#include "core/error.hpp"
#include "mesh/gltf_accessors.hpp"
#include "mesh/gltf_input.hpp"

namespace spx {

using namespace detail;

namespace {

// The float sampler `sampler`'s times and values, where its accessors are as the spec says (none
// where not: left to assimp); `n` and `type` receive the values' components per element and type.
bool sampler_data(const GltfFile& file, const json& sampler, const std::string& path, std::vector<double>& times,
                  std::vector<double>& values, size_t& n, std::string& type) {
  const size_t input = gltf_whole_number(sampler, "input", SIZE_MAX, path, "a clip's sampler");
  const size_t output = gltf_whole_number(sampler, "output", SIZE_MAX, path, "a clip's sampler");
  const json& accessors = file.doc["accessors"];
  if (input >= accessors.size() || output >= accessors.size() || !accessors[input].is_object() ||
      !accessors[output].is_object())
    fail_input(path, "a clip's sampler names an accessor that does not exist");
  const json& in = accessors[input];
  const json& out = accessors[output];
  if (!in.contains("componentType") || in["componentType"] != kFloat || components(in) != 1 ||
      !out.contains("componentType") || out["componentType"] != kFloat || components(out) == 0)
    return false;
  times = accessor_values(file, in, path);
  values = accessor_values(file, out, path);
  n = components(out);
  type = text(out, "type");
  return true;
}

// How many clips the samplers' rewrites read: none where the clips or accessors are no lists
// (left to assimp).
size_t sampled_clips(const json& doc) {
  const auto list = [&](const char* key) { return doc.contains(key) && doc[key].is_array(); };
  return list("animations") && list("accessors") ? doc["animations"].size() : 0;
}

// Clip a's samplers, or none where it has no list of them.
json* samplers_of(json& doc, size_t a) {
  json& clip = doc["animations"][a];
  return clip.is_object() && clip.contains("samplers") && clip["samplers"].is_array() ? &clip["samplers"] : nullptr;
}

// A node's translation, rotation or scale as glTF gives it (or its default); empty where it is
// not a list of numbers of the path's size.
std::vector<double> node_path_value(const json& node, const std::string& path) {
  const std::vector<double> fallback = path == "rotation" ? std::vector<double>{0, 0, 0, 1}
                                       : path == "scale"  ? std::vector<double>{1, 1, 1}
                                                          : std::vector<double>{0, 0, 0};
  if (!node.contains(path)) return fallback;
  const json& v = node[path];
  if (!v.is_array() || v.size() != fallback.size()) return {};
  std::vector<double> out;
  for (const json& c : v) {
    if (!c.is_number()) return {};
    out.push_back(c.get<double>());
  }
  return out;
}

// The node (or mesh) and path a KHR_animation_pointer names, where it is "/nodes/N/<path>" or
// "/meshes/M/weights" (N and M written as JSON pointers write a list's index: no sign, no leading
// zero); neither otherwise.
void pointed_object(const std::string& pointer, ChannelTarget& out) {
  for (const std::string head : {"/nodes/", "/meshes/"}) {
    if (pointer.rfind(head, 0) != 0) continue;
    const size_t slash = pointer.find('/', head.size());
    if (slash == std::string::npos) return;
    const std::string digits = pointer.substr(head.size(), slash - head.size());
    if (digits.empty() || digits.size() > 9 || (digits.size() > 1 && digits[0] == '0') ||
        digits.find_first_not_of("0123456789") != std::string::npos)
      return;
    out.path = pointer.substr(slash + 1);
    if (head == "/nodes/") out.node = std::stoul(digits);
    else if (out.path == "weights") out.mesh = std::stoul(digits);
  }
}

// Where a clip's mesh weights go: every node placing `mesh` without weights of its own.
std::vector<size_t> nodes_taking_weights_of(const json& doc, size_t mesh) {
  std::vector<size_t> out;
  if (!doc.contains("nodes") || !doc["nodes"].is_array()) return out;
  const json& nodes = doc["nodes"];
  for (size_t n = 0; n < nodes.size(); ++n)
    if (nodes[n].is_object() && nodes[n].contains("mesh") && nodes[n]["mesh"] == mesh && !nodes[n].contains("weights"))
      out.push_back(n);
  return out;
}

bool moves_a_node(const std::string& path) {
  return path == "translation" || path == "rotation" || path == "scale" || path == "weights";
}

}  // namespace

ChannelTarget detail::channel_target(const json& channel) {
  ChannelTarget out;
  if (!channel.is_object() || !channel.contains("target") || !channel["target"].is_object()) return out;
  const json& target = channel["target"];
  out.path = text(target, "path");
  if (out.path == "pointer") {
    out.path.clear();
    const json extensions = target.value("extensions", json::object());
    const json pointer = extensions.is_object() ? extensions.value("KHR_animation_pointer", json::object()) : json();
    if (pointer.is_object()) out.pointer = text(pointer, "pointer");
    pointed_object(out.pointer, out);
  } else if (target.contains("node") && is_index(target["node"])) {
    out.node = target["node"].get<size_t>();
  }
  if (!moves_a_node(out.path)) out.node = out.mesh = SIZE_MAX;
  return out;
}

size_t channels_as_assimp_reads(GltfFile& file, std::vector<std::vector<std::string>>& passed_over) {
  json& doc = file.doc;
  const bool clips = doc.contains("animations") && doc["animations"].is_array();
  passed_over.assign(clips ? doc["animations"].size() : 0, {});
  size_t changed = 0;
  for (size_t a = 0; a < passed_over.size(); ++a) {
    json& clip = doc["animations"][a];
    if (!clip.is_object() || !clip.contains("channels") || !clip["channels"].is_array()) continue;
    json kept = json::array();
    const json& channels = clip["channels"];
    for (size_t c = 0; c < channels.size(); ++c) {
      const ChannelTarget moved = channel_target(channels[c]);
      const std::vector<size_t> nodes = moved.node != SIZE_MAX   ? std::vector<size_t>{moved.node}
                                        : moved.mesh != SIZE_MAX ? nodes_taking_weights_of(doc, moved.mesh)
                                                                 : std::vector<size_t>{};
      if (moved.pointer.empty() && !nodes.empty()) {
        kept.push_back(channels[c]);
      } else if (!nodes.empty()) {
        for (size_t node : nodes) {
          json channel = channels[c];
          channel["target"] = {{"node", node}, {"path", moved.path}};
          kept.push_back(std::move(channel));
        }
        ++changed;
      } else {
        const json target = channels[c].is_object() ? channels[c].value("target", json::object()) : json::object();
        const std::string path = target.is_object() ? text(target, "path") : "";
        const std::string what = moved.mesh != SIZE_MAX ? "KHR_animation_pointer '" + moved.pointer +
                                                              "': no node places meshes[" + std::to_string(moved.mesh) +
                                                              "] without weights of its own"
                                 : !moved.pointer.empty() ? "KHR_animation_pointer '" + moved.pointer + "'"
                                 : path == "pointer"      ? "a pointer channel without its pointer"
                                 : !moves_a_node(path)    ? "path '" + path + "'"
                                                          : "no target node";
        passed_over[a].push_back("animations[" + std::to_string(a) + "].channels[" + std::to_string(c) + "] (" +
                                 what + ")");
        ++changed;
      }
    }
    clip["channels"] = std::move(kept);
  }
  return changed;
}

size_t complete_mirrored_channels(GltfFile& file, const std::string& path) {
  json& doc = file.doc;
  if (!doc.contains("animations") || !doc["animations"].is_array() || !doc.contains("nodes")) return 0;
  const json nodes = doc["nodes"];
  size_t added = 0;
  for (json& clip : doc["animations"]) {
    if (!clip.is_object() || !clip.contains("channels") || !clip["channels"].is_array() || !clip.contains("samplers") ||
        !clip["samplers"].is_array())
      continue;
    // Per mirrored node the clip moves: the paths it moves, and the first key time of one of them.
    std::map<size_t, std::set<std::string>> moved;
    std::map<size_t, double> first_time;
    for (const json& channel : clip["channels"]) {
      if (!channel.is_object() || !channel.contains("target") || !channel["target"].is_object()) continue;
      const json& target = channel["target"];
      const std::string p = text(target, "path");
      if (!target.contains("node") || !is_index(target["node"]) || (p != "translation" && p != "rotation" && p != "scale"))
        continue;
      const size_t n = size_t(target["node"].get<int64_t>());
      if (n >= nodes.size() || !nodes[n].is_object()) continue;
      const std::vector<double> scale = node_path_value(nodes[n], "scale");
      if (scale.empty() || !(scale[0] * scale[1] * scale[2] < 0)) continue;
      moved[n].insert(p);
      if (first_time.count(n) || !channel.contains("sampler") || !is_index(channel["sampler"])) continue;
      const size_t s = size_t(channel["sampler"].get<int64_t>());
      if (s >= clip["samplers"].size() || !clip["samplers"][s].is_object() || !clip["samplers"][s].contains("input")) continue;
      const json& input = clip["samplers"][s]["input"];
      if (!is_index(input) || !doc.contains("accessors") || !doc["accessors"].is_array() ||
          size_t(input.get<int64_t>()) >= doc["accessors"].size())
        continue;
      const json& accessor = doc["accessors"][size_t(input.get<int64_t>())];
      if (!accessor.is_object() || !accessor.contains("componentType") || accessor["componentType"] != kFloat ||
          components(accessor) != 1)
        continue;
      const std::vector<double> times = accessor_values(file, accessor, path);
      if (!times.empty()) first_time[n] = times[0];
    }
    for (const auto& [n, paths] : moved) {
      if (!first_time.count(n)) continue;
      for (const char* missing : {"translation", "rotation", "scale"}) {
        if (paths.count(missing)) continue;
        const std::vector<double> value = node_path_value(nodes[n], missing);
        if (value.empty()) continue;
        const size_t input = add_float_accessor(file, {first_time[n]}, "SCALAR");
        const size_t output = add_float_accessor(file, value, value.size() == 4 ? "VEC4" : "VEC3");
        clip["samplers"].push_back({{"input", input}, {"output", output}, {"interpolation", "LINEAR"}});
        clip["channels"].push_back({{"sampler", clip["samplers"].size() - 1}, {"target", {{"node", n}, {"path", missing}}}});
        ++added;
      }
    }
  }
  return added;
}

size_t step_samplers_as_held_keys(GltfFile& file, const std::string& path) {
  json& doc = file.doc;
  size_t changed = 0;
  for (size_t a = 0; a < sampled_clips(doc); ++a) {
    json* samplers = samplers_of(doc, a);
    if (!samplers) continue;
    for (json& sampler : *samplers) {
      if (!sampler.is_object() || text(sampler, "interpolation") != "STEP") continue;
      std::vector<double> times, values;
      size_t n = 0;
      std::string type;
      if (!sampler_data(file, sampler, path, times, values, n, type)) continue;  // not as the spec says: left to assimp
      const size_t keys = times.size();
      if (keys < 2 || values.size() % (keys * n) != 0) continue;
      const size_t per_key = values.size() / keys;  // a morph weights' key holds one value per target
      std::vector<double> held_times = {times[0]}, held_values(values.begin(), values.begin() + long(per_key));
      for (size_t k = 1; k < keys; ++k) {
        held_times.insert(held_times.end(), {times[k], times[k]});
        held_values.insert(held_values.end(), values.begin() + long((k - 1) * per_key), values.begin() + long(k * per_key));
        held_values.insert(held_values.end(), values.begin() + long(k * per_key), values.begin() + long((k + 1) * per_key));
      }
      sampler["input"] = add_float_accessor(file, held_times, "SCALAR");
      sampler["output"] = add_float_accessor(file, held_values, type);
      sampler["interpolation"] = "LINEAR";
      ++changed;
    }
  }
  return changed;
}

namespace {

// The Hermite spline of glTF's cubic sampler between keys k and k + 1 at s in [0, 1] (a key's
// values: its in-tangent, value and out-tangent, `width` numbers each), a rotation normalized.
std::vector<double> cubic_value(const std::vector<double>& times, const std::vector<double>& values, size_t width,
                                size_t k, double s, bool rotation) {
  const double td = times[k + 1] - times[k], s2 = s * s, s3 = s2 * s;
  const double* v0 = &values[(3 * k + 1) * width];
  const double* b0 = &values[(3 * k + 2) * width];
  const double* a1 = &values[(3 * k + 3) * width];
  const double* v1 = &values[(3 * k + 4) * width];
  std::vector<double> p(width);
  for (size_t c = 0; c < width; ++c)
    p[c] = (2 * s3 - 3 * s2 + 1) * v0[c] + td * (s3 - 2 * s2 + s) * b0[c] + (-2 * s3 + 3 * s2) * v1[c] +
           td * (s3 - s2) * a1[c];
  if (rotation) {
    double norm = 0;
    for (double c : p) norm += c * c;
    norm = std::sqrt(norm);
    if (norm > 0)
      for (double& c : p) c /= norm;
  }
  return p;
}

}  // namespace

size_t cubic_samplers_as_keys(GltfFile& file, const std::string& path, std::vector<AddedKeys>& added) {
  json& doc = file.doc;
  size_t changed = 0;
  added.assign(sampled_clips(doc), {});
  const auto cubic = [](const json& sampler) { return sampler.is_object() && text(sampler, "interpolation") == "CUBICSPLINE"; };
  for (size_t a = 0; a < added.size(); ++a) {
    json* samplers = samplers_of(doc, a);
    if (!samplers || std::none_of(samplers->begin(), samplers->end(), cubic)) continue;
    std::vector<double> asset_times;
    for (json& sampler : *samplers) {
      std::vector<double> times, values;
      size_t n = 0;
      std::string type;
      if (!sampler.is_object() || !sampler_data(file, sampler, path, times, values, n, type)) continue;
      asset_times.insert(asset_times.end(), times.begin(), times.end());
      if (!cubic(sampler)) continue;
      const size_t keys = times.size();
      if (keys == 0 || values.size() % (3 * keys * n) != 0) continue;  // not as the spec says: left to assimp
      const size_t width = values.size() / (3 * keys);  // a morph weights' key holds one value per target
      const bool rotation = n == 4;
      std::vector<double> new_times, new_values;
      for (size_t k = 0; k < keys; ++k) {
        new_times.push_back(times[k]);
        new_values.insert(new_values.end(), values.begin() + long((3 * k + 1) * width),
                          values.begin() + long((3 * k + 2) * width));
        if (k + 1 == keys || !(times[k + 1] > times[k]) || !std::isfinite(times[k + 1] - times[k])) continue;
        const int steps = clip_steps_between(times[k + 1] - times[k]);
        for (int i = 1; i < steps; ++i) {
          const double s = double(i) / steps;
          new_times.push_back(times[k] + s * (times[k + 1] - times[k]));
          const std::vector<double> p = cubic_value(times, values, width, k, s, rotation);
          new_values.insert(new_values.end(), p.begin(), p.end());
          ++added[a].added;
        }
      }
      sampler["input"] = add_float_accessor(file, new_times, "SCALAR");
      sampler["output"] = add_float_accessor(file, new_values, type);
      sampler["interpolation"] = "LINEAR";
      ++changed;
    }
    if (added[a].added == 0) continue;
    std::sort(asset_times.begin(), asset_times.end());
    asset_times.erase(std::unique(asset_times.begin(), asset_times.end()), asset_times.end());
    added[a].asset_times = std::move(asset_times);
  }
  return changed;
}

}  // namespace spx
