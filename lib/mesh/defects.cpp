#include "mesh/defects.hpp"

#include <algorithm>
#include <numeric>

#include "core/format.hpp"
#include "mesh/components.hpp"
#include "mesh/winding_number.hpp"

namespace spx {

bool is_degenerate(const TriMesh& mesh, int t, double diagonal) {
  const Eigen::Vector3i& f = mesh.triangles[t];
  if (f[0] == f[1] || f[1] == f[2] || f[0] == f[2]) return true;
  const Eigen::Vector3d& a = mesh.vertices[f[0]];
  const double area2 = (mesh.vertices[f[1]] - a).cross(mesh.vertices[f[2]] - a).norm();
  return area2 <= 1e-14 * diagonal * diagonal;
}

namespace {

// The closed pieces (every edge of theirs used twice, in opposite directions) of negative volume
// whose first corner the other pieces' winding number puts outside.
std::vector<std::string> inside_out_parts(const TriMesh& mesh, const Components& parts, const std::vector<EdgeUse>& half) {
  std::vector<char> closed(parts.count, 1);
  for (size_t i = 0; i < half.size();) {
    size_t j = i;
    while (j < half.size() && half[j].lo == half[i].lo && half[j].hi == half[i].hi) ++j;
    if (j - i != 2 || half[i].forward == half[i + 1].forward) closed[size_t(parts.of_triangle[size_t(half[i].tri)])] = 0;
    i = j;
  }
  std::vector<double> volume(parts.count, 0);
  std::vector<size_t> count(parts.count, 0);
  std::vector<Eigen::Vector3d> sum(parts.count, Eigen::Vector3d::Zero());
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& f = mesh.triangles[t];
    const size_t p = size_t(parts.of_triangle[t]);
    volume[p] += mesh.vertices[f[0]].dot(mesh.vertices[f[1]].cross(mesh.vertices[f[2]])) / 6.0;
    ++count[p];
    sum[p] += (mesh.vertices[f[0]] + mesh.vertices[f[1]] + mesh.vertices[f[2]]) / 3;
  }
  std::vector<std::string> out;
  for (size_t p = 0; p < parts.count; ++p) {
    if (!closed[p] || !(volume[p] < 0)) continue;
    const size_t first = size_t(std::find(parts.of_triangle.begin(), parts.of_triangle.end(), int(p)) - parts.of_triangle.begin());
    TriMesh others;
    others.vertices = mesh.vertices;
    for (size_t t = 0; t < mesh.triangles.size(); ++t)
      if (size_t(parts.of_triangle[t]) != p) others.triangles.push_back(mesh.triangles[t]);
    if (winding_number_exact(others, mesh.vertices[size_t(mesh.triangles[first][0])]) > 0.5) continue;  // a cavity
    const Eigen::Vector3d c = sum[p] / double(count[p]);
    out.push_back("part " + std::to_string(p + 1) + " of " + std::to_string(parts.count) + " (" +
                  std::to_string(count[p]) + " triangles around " + num(c.x()) + ", " + num(c.y()) + ", " + num(c.z()) + ")");
  }
  return out;
}

}  // namespace

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
  const Components parts = components_of(mesh.triangles.size(), half);
  d.components = parts.count;
  d.inside_out_parts = inside_out_parts(mesh, parts, half);
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
          {"inside_out_parts", inside_out_parts},
          {"watertight", watertight()}};
}

}  // namespace spx
