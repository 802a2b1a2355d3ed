#include "io/gltf_morph.hpp"

#include <cstring>

#include "core/error.hpp"
#include "core/json_io.hpp"

namespace spx {
namespace {

// Through a volatile: GCC 12 at -O3 turned double(float(x)) back into x for vectorised pairs
// of components, skipping the very rounding this file is about.
float round_to_float(double x) {
  volatile float f = float(x);
  return f;
}
Eigen::Vector3f to_float(const Eigen::Vector3d& p) {
  return Eigen::Vector3f(round_to_float(p.x()), round_to_float(p.y()), round_to_float(p.z()));
}
Eigen::Vector3d to_double(const Eigen::Vector3f& p) { return Eigen::Vector3d(double(p.x()), double(p.y()), double(p.z())); }

// The single-precision displacement glTF stores for one target vertex.
Eigen::Vector3f displacement(const MorphAsset& asset, size_t target, size_t v) {
  return to_float(asset.targets[target][v]) - to_float(asset.base.vertices[v]);
}

// One binary buffer with a view and an accessor per array.
struct GlbBuilder {
  std::string bin;
  json views = json::array(), accessors = json::array();

  int add(const void* data, size_t bytes, json accessor) {
    while (bin.size() % 4) bin += '\0';
    views.push_back({{"buffer", 0}, {"byteOffset", bin.size()}, {"byteLength", bytes}});
    bin.append(static_cast<const char*>(data), bytes);
    accessor["bufferView"] = views.size() - 1;
    accessors.push_back(std::move(accessor));
    return int(accessors.size()) - 1;
  }
  int add_vec3(const std::vector<Eigen::Vector3f>& v) {
    Eigen::Vector3f lo = Eigen::Vector3f::Constant(INFINITY), hi = -lo;
    for (const auto& p : v) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
    return add(v.data(), v.size() * sizeof(Eigen::Vector3f),
               {{"componentType", 5126}, {"type", "VEC3"}, {"count", v.size()},
                {"min", {lo.x(), lo.y(), lo.z()}}, {"max", {hi.x(), hi.y(), hi.z()}}});
  }
  int add_floats(const std::vector<float>& v, bool bounds) {
    json a = {{"componentType", 5126}, {"type", "SCALAR"}, {"count", v.size()}};
    if (bounds && !v.empty()) a["min"] = {v.front()}, a["max"] = {v.back()};
    return add(v.data(), v.size() * sizeof(float), std::move(a));
  }
};

void put32(std::string& s, uint32_t v) {
  for (int i = 0; i < 4; ++i) s += char((v >> (8 * i)) & 0xff);
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
  GlbBuilder b;
  std::vector<Eigen::Vector3f> base;
  for (const auto& p : asset.base.vertices) base.push_back(to_float(p));
  const int position = b.add_vec3(base);
  std::vector<uint32_t> indices;
  for (const auto& t : asset.base.triangles)
    for (int c = 0; c < 3; ++c) indices.push_back(uint32_t(t[c]));
  const int index = b.add(indices.data(), indices.size() * 4,
                          {{"componentType", 5125}, {"type", "SCALAR"}, {"count", indices.size()}});
  json targets = json::array();
  for (size_t t = 0; t < k; ++t) {
    if (asset.targets[t].size() != n) fail_usage(asset.target_names[t], "target has another vertex count than the base");
    std::vector<Eigen::Vector3f> d;
    for (size_t v = 0; v < n; ++v) d.push_back(displacement(asset, t, v));
    targets.push_back({{"POSITION", b.add_vec3(d)}});
  }
  // The clip: key 0 all zero, key j + 1 weight 1 on target j.
  std::vector<float> times, weights;
  for (size_t key = 0; k && key <= k; ++key) {
    times.push_back(float(key));
    for (size_t t = 0; t < k; ++t) weights.push_back(key == t + 1 ? 1.0f : 0.0f);
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
              {"meshes", {mesh}},
              {"accessors", b.accessors},
              {"bufferViews", b.views},
              {"buffers", {{{"byteLength", b.bin.size()}}}}};
  if (k) {
    const json sampler = {{"input", input}, {"output", output}, {"interpolation", "LINEAR"}};
    const json channel = {{"sampler", 0}, {"target", {{"node", 0}, {"path", "weights"}}}};
    doc["animations"] = json::array({json{{"name", asset.name}, {"samplers", json::array({sampler})},
                                          {"channels", json::array({channel})}}});
  }

  std::string text = doc.dump();
  while (text.size() % 4) text += ' ';
  while (b.bin.size() % 4) b.bin += '\0';
  std::string out = "glTF";
  put32(out, 2);
  put32(out, uint32_t(12 + 8 + text.size() + 8 + b.bin.size()));
  put32(out, uint32_t(text.size()));
  out += "JSON";
  out += text;
  put32(out, uint32_t(b.bin.size()));
  out.append("BIN\0", 4);
  out += b.bin;
  return out;
}

}  // namespace spx
