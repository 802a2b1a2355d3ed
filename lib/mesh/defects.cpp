#include "mesh/defects.hpp"

#include <algorithm>
#include <numeric>

#include "mesh/components.hpp"

namespace spx {

bool is_degenerate(const TriMesh& mesh, int t, double diagonal) {
  const Eigen::Vector3i& f = mesh.triangles[t];
  if (f[0] == f[1] || f[1] == f[2] || f[0] == f[2]) return true;
  const Eigen::Vector3d& a = mesh.vertices[f[0]];
  const double area2 = (mesh.vertices[f[1]] - a).cross(mesh.vertices[f[2]] - a).norm();
  return area2 <= 1e-14 * diagonal * diagonal;
}

MeshDefects find_defects(const TriMesh& mesh) {
  MeshDefects d;
  d.vertices = mesh.vertices.size();
  d.triangles = mesh.triangles.size();
  const double diag = mesh.diagonal();

  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& f = mesh.triangles[t];
    if (is_degenerate(mesh, static_cast<int>(t), diag)) ++d.degenerate_triangles;
    const Eigen::Vector3d& p0 = mesh.vertices[f[0]];
    d.signed_volume += p0.dot(mesh.vertices[f[1]].cross(mesh.vertices[f[2]])) / 6.0;
  }
  // An edge's uses: counts and orientation per edge, and (one sort for both) the pieces.
  const std::vector<EdgeUse> half = sorted_edge_uses(mesh);
  for (size_t i = 0; i < half.size();) {
    size_t j = i;
    while (j < half.size() && half[j].lo == half[i].lo && half[j].hi == half[i].hi) ++j;
    const size_t n = j - i;
    if (n == 1) ++d.boundary_edges;
    else if (n > 2) ++d.non_manifold_edges;
    else if (half[i].forward == half[i + 1].forward) ++d.inconsistent_edges;
    i = j;
  }
  d.components = components_of(mesh.triangles.size(), half).count;
  return d;
}

nlohmann::json MeshDefects::to_json() const {
  return {{"vertices", vertices},
          {"triangles", triangles},
          {"boundary_edges", boundary_edges},
          {"non_manifold_edges", non_manifold_edges},
          {"inconsistent_edges", inconsistent_edges},
          {"degenerate_triangles", degenerate_triangles},
          {"components", components},
          {"signed_volume", signed_volume},
          {"watertight", watertight()}};
}

}  // namespace spx
