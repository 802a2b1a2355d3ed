#pragma once
// Accuracy as the paper measures it: distance from mesh vertices to the surface of the union
// of spheres (negative where the vertex is inside the union).
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/sphere.hpp"
#include "mesh/mesh.hpp"

namespace spx {

// Signed distance from each point to the union's surface: min_j (|p - c_j| - r_j).
// Spheres with zero radius are absent from the union.
std::vector<double> union_signed_distance(const std::vector<Eigen::Vector3d>& points, const SphereSet& spheres);

struct ErrorStats {
  double median = 0, p95 = 0, max = 0;
  size_t count = 0;
  nlohmann::json to_json() const { return {{"median", median}, {"p95", p95}, {"max", max}, {"vertices", count}}; }
};

// Statistics of |values|.
ErrorStats summarize_abs(const std::vector<double>& values);

// A pose's mesh with its spheres and each vertex's signed distance to their union: what the
// error pictures colour and the metrics summarise.
struct PoseError {
  std::string name;
  TriMesh mesh;
  SphereSet spheres;
  std::vector<double> vertex_error;  // signed, per vertex
};

inline ErrorStats vertex_error(const TriMesh& mesh, const SphereSet& spheres) {
  return summarize_abs(union_signed_distance(mesh.vertices, spheres));
}

}  // namespace spx
