#pragma once
// io internals: one binary glTF buffer built array by array (a view and an accessor each), and
// the GLB container around a glTF document. The glTF writers (morph targets, rigs) share it.
#include <string>
#include <vector>

#include "core/json_io.hpp"
#include "mesh/mesh.hpp"

namespace spx::detail {

// Single precision as glTF stores it, rounded through a volatile: GCC 12 at -O3 turned
// double(float(x)) back into x for vectorised pairs of components, skipping the rounding.
inline float round_to_float(double x) {
  volatile float f = float(x);
  return f;
}
inline Eigen::Vector3f to_float(const Eigen::Vector3d& p) {
  return Eigen::Vector3f(round_to_float(p.x()), round_to_float(p.y()), round_to_float(p.z()));
}
inline Eigen::Vector3d to_double(const Eigen::Vector3f& p) {
  return Eigen::Vector3d(double(p.x()), double(p.y()), double(p.z()));
}

struct GlbBuilder {
  std::string bin;
  json views = json::array(), accessors = json::array();

  int add(const void* data, size_t bytes, json accessor);
  int add_vec3(const std::vector<Eigen::Vector3f>& v);                      // with min/max
  int add_floats(const std::vector<float>& v, bool bounds);                 // SCALAR; bounds: ascending input
  int add_vec4(const std::vector<float>& xyzw);                             // VEC4 (rotations)
  int add_indices(const std::vector<Eigen::Vector3i>& triangles);           // uint32 SCALAR
  // The finished file: `doc` gets its buffer, views and accessors, then JSON and BIN chunks.
  std::string glb(json doc);
};

}  // namespace spx::detail
