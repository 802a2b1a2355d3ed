#include "io/gltf_morph.hpp"

#include <cstring>

#include "core/error.hpp"
#include "core/json_io.hpp"
#include "io/glb_builder.hpp"

namespace spx {
using detail::to_double;
using detail::to_float;
namespace {

// The single-precision displacement glTF stores for one target vertex.
Eigen::Vector3f displacement(const MorphAsset& asset, size_t target, size_t v) {
  return to_float(asset.targets[target][v]) - to_float(asset.base.vertices[v]);
}

}  // namespace

std::vector<Eigen::Vector3d> stored_base(const MorphAsset& asset) {
  std::vector<Eigen::Vector3d> out;
  for (const auto& p : asset.base.vertices) out.push_back(to_double(to_float(p)));
  return out;
}

std::vector<Eigen::Vector3d> stored_target(const MorphAsset& asset, size_t target) {
  std::vector<Eigen::Vector3d> out;
  for (size_t v = 0; v < asset.base.vertices.size(); ++v) {
    const Eigen::Vector3f sum = to_float(asset.base.vertices[v]) + displacement(asset, target, v);
    out.push_back(to_double(sum));
  }
  return out;
}

std::string encode_morph_glb(const MorphAsset& asset) {
  const size_t n = asset.base.vertices.size(), k = asset.targets.size();
  if (asset.target_names.size() != k) fail_usage(asset.name, "one name per morph target");
  detail::GlbBuilder b;
  std::vector<Eigen::Vector3f> base;
  for (const auto& p : asset.base.vertices) base.push_back(to_float(p));
  const int position = b.add_vec3(base);
  const int index = b.add_indices(asset.base.triangles);
  json targets = json::array();
  for (size_t t = 0; t < k; ++t) {
    if (asset.targets[t].size() != n) fail_usage(asset.target_names[t], "target has another vertex count than the base");
    std::vector<Eigen::Vector3f> d;
    for (size_t v = 0; v < n; ++v) d.push_back(displacement(asset, t, v));
    targets.push_back({{"POSITION", b.add_vec3(d)}});
  }
  // The clip: key 0 all zero, key j + 1 weight 1 on target j, then (two targets or more) every
  // target at 1 at once, as a mesh adds them.
  std::vector<float> times, weights;
  const size_t last = k > 1 ? k + 1 : k;
  for (size_t key = 0; k && key <= last; ++key) {
    times.push_back(float(key));
    for (size_t t = 0; t < k; ++t) weights.push_back(key == t + 1 || key == k + 1 ? 1.0f : 0.0f);
  }
  const int input = k ? b.add_floats(times, true) : -1, output = k ? b.add_floats(weights, false) : -1;

  json primitive = {{"attributes", {{"POSITION", position}}}, {"indices", index}, {"mode", 4}};
  if (k) primitive["targets"] = targets;
  json mesh = {{"name", asset.name}, {"primitives", {primitive}}};
  if (k) mesh["weights"] = std::vector<float>(k, 0.0f), mesh["extras"] = {{"targetNames", asset.target_names}};
  json doc = {{"asset", {{"version", "2.0"}, {"generator", "spx"}}},
              {"scene", 0},
              {"scenes", {{{"nodes", {0}}}}},
              {"nodes", {{{"name", asset.name}, {"mesh", 0}}}},
              {"meshes", {mesh}}};
  if (k) {
    const json sampler = {{"input", input}, {"output", output}, {"interpolation", "LINEAR"}};
    const json channel = {{"sampler", 0}, {"target", {{"node", 0}, {"path", "weights"}}}};
    doc["animations"] = json::array({json{{"name", asset.name}, {"samplers", json::array({sampler})},
                                          {"channels", json::array({channel})}}});
  }

  return b.glb(std::move(doc));
}

}  // namespace spx
