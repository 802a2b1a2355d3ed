#include "io/glb_builder.hpp"

#include <cmath>

#include "core/gltf_file.hpp"

namespace spx::detail {

int GlbBuilder::add(const void* data, size_t bytes, json accessor) {
  while (bin.size() % 4) bin += '\0';
  views.push_back({{"buffer", 0}, {"byteOffset", bin.size()}, {"byteLength", bytes}});
  bin.append(static_cast<const char*>(data), bytes);
  accessor["bufferView"] = views.size() - 1;
  accessors.push_back(std::move(accessor));
  return int(accessors.size()) - 1;
}

int GlbBuilder::add_vec3(const std::vector<Eigen::Vector3f>& v) {
  Eigen::Vector3f lo = Eigen::Vector3f::Constant(INFINITY), hi = -lo;
  for (const auto& p : v) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  return add(v.data(), v.size() * sizeof(Eigen::Vector3f),
             {{"componentType", 5126}, {"type", "VEC3"}, {"count", v.size()},
              {"min", {lo.x(), lo.y(), lo.z()}}, {"max", {hi.x(), hi.y(), hi.z()}}});
}

int GlbBuilder::add_floats(const std::vector<float>& v, bool bounds) {
  json a = {{"componentType", 5126}, {"type", "SCALAR"}, {"count", v.size()}};
  if (bounds && !v.empty()) a["min"] = {v.front()}, a["max"] = {v.back()};
  return add(v.data(), v.size() * sizeof(float), std::move(a));
}

int GlbBuilder::add_vec4(const std::vector<float>& xyzw) {
  return add(xyzw.data(), xyzw.size() * sizeof(float),
             {{"componentType", 5126}, {"type", "VEC4"}, {"count", xyzw.size() / 4}});
}

int GlbBuilder::add_indices(const std::vector<Eigen::Vector3i>& triangles) {
  std::vector<uint32_t> indices;
  for (const auto& t : triangles)
    for (int c = 0; c < 3; ++c) indices.push_back(uint32_t(t[c]));
  return add(indices.data(), indices.size() * 4, {{"componentType", 5125}, {"type", "SCALAR"}, {"count", indices.size()}});
}

std::string GlbBuilder::glb(json doc) {
  doc["accessors"] = accessors;
  doc["bufferViews"] = views;
  doc["buffers"] = json::array({json::object()});
  return encode_glb({std::move(doc), bin});
}

}  // namespace spx::detail
