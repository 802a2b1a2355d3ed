#include "mesh/defects.hpp"

#include <algorithm>

#include "core/format.hpp"
#include "mesh/components.hpp"
#include "mesh/winding_number.hpp"

namespace spx {

bool is_degenerate(const TriMesh& mesh, int t, double diagonal) {
  const Eigen::Vector3i& f = mesh.triangles[t];
  if (f[0] == f[1] || f[1] == f[2] || f[0] == f[2]) return true;
  return is_degenerate(mesh.vertices[f[0]], mesh.vertices[f[1]], mesh.vertices[f[2]], diagonal);
}

bool is_degenerate(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c, double diagonal) {
  const double area2 = (b - a).cross(c - a).norm();
  return area2 <= 1e-14 * diagonal * diagonal;
}

namespace {

// How find_defects names a piece.
std::string part_name(size_t p, const std::vector<PieceShape>& parts) {
  return piece_name("part", p + 1, parts.size(), parts[p]);
}

// The closed pieces (`closed`: every edge of theirs used twice, in opposite directions) of
// negative volume whose first corner the other pieces' winding number puts outside.
std::vector<std::string> inside_out_parts(const TriMesh& mesh, const Components& components,
                                          const std::vector<PieceShape>& parts, const std::vector<char>& closed) {
  std::vector<std::string> out;
  for (size_t p = 0; p < parts.size(); ++p) {
    if (!closed[p] || !(parts[p].volume < 0)) continue;
    TriMesh others;
    others.vertices = mesh.vertices;
    int corner = -1;
    for (size_t t = 0; t < mesh.triangles.size(); ++t)
      if (size_t(components.of_triangle[t]) != p)
        others.triangles.push_back(mesh.triangles[t]);
      else if (corner < 0)
        corner = mesh.triangles[t][0];
    if (winding_number_exact(others, mesh.vertices[size_t(corner)]) > 0.5) continue;  // a cavity
    out.push_back(part_name(p, parts));
  }
  return out;
}

// Pieces of at most 1 % of the triangles whose removal shrinks the diagonal by a fifth or more:
// each piece's box against the union of every other's (prefix and suffix unions).
std::vector<std::string> far_parts(const std::vector<PieceShape>& parts, size_t triangles) {
  const size_t n = parts.size();
  if (n < 2) return {};
  std::vector<Eigen::AlignedBox3d> before(n + 1), after(n + 1);
  for (size_t p = 0; p < n; ++p) before[p + 1] = before[p].merged(parts[p].box);
  for (size_t p = n; p-- > 0;) after[p] = after[p + 1].merged(parts[p].box);
  const double whole = before[n].diagonal().norm();
  std::vector<std::string> out;
  for (size_t p = 0; p < n; ++p) {
    if (100 * parts[p].triangles > triangles) continue;
    const double rest = before[p].merged(after[p + 1]).diagonal().norm();
    if (rest > 0.8 * whole) continue;
    out.push_back(part_name(p, parts) + " stretches the diagonal from " + num(rest) + " to " + num(whole));
  }
  return out;
}

}  // namespace

double signed_volume(const TriMesh& mesh) {
  double v = 0;
  for (const auto& f : mesh.triangles) v += mesh.vertices[f[0]].dot(mesh.vertices[f[1]].cross(mesh.vertices[f[2]])) / 6.0;
  return v;
}

MeshDefects find_defects(const TriMesh& mesh) {
  MeshDefects d;
  d.vertices = mesh.vertices.size();
  d.triangles = mesh.triangles.size();
  const double diag = mesh.diagonal();

  for (size_t t = 0; t < mesh.triangles.size(); ++t)
    if (is_degenerate(mesh, static_cast<int>(t), diag)) ++d.degenerate_triangles;
  d.signed_volume = signed_volume(mesh);
  // An edge's uses: counts and orientation per edge, and (one sort for both) the pieces, each
  // closed where none of its edges is a defect.
  const std::vector<EdgeUse> half = sorted_edge_uses(mesh);
  const Components components = components_of(mesh.triangles.size(), half);
  d.components = components.count;
  std::vector<char> closed(components.count, 1);
  for (size_t i = 0; i < half.size();) {
    size_t j = i;
    while (j < half.size() && half[j].lo == half[i].lo && half[j].hi == half[i].hi) ++j;
    const size_t n = j - i;
    const size_t forward = size_t(std::count_if(half.begin() + std::ptrdiff_t(i), half.begin() + std::ptrdiff_t(j),
                                                 [](const EdgeUse& u) { return u.forward; }));
    d.encloses = d.encloses && 2 * forward == n;
    if (n == 1) ++d.boundary_edges;
    else if (n > 2) ++d.non_manifold_edges;
    else if (half[i].forward == half[i + 1].forward) ++d.inconsistent_edges;
    else {
      i = j;
      continue;
    }
    closed[size_t(components.of_triangle[size_t(half[i].tri)])] = 0;
    i = j;
  }
  const std::vector<PieceShape> parts = piece_shapes(mesh, components);
  d.inside_out_parts = inside_out_parts(mesh, components, parts, closed);
  d.far_parts = far_parts(parts, mesh.triangles.size());
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
          {"far_parts", far_parts},
          {"watertight", watertight()}};
}

}  // namespace spx
