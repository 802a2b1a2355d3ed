#include "mesh/near_boundary.hpp"

#include <CGAL/Simple_cartesian.h>

#include <cmath>
#include <limits>

#include "mesh/defects.hpp"

namespace spx {
namespace {
using K = CGAL::Simple_cartesian<double>;
K::Point_3 to_cgal(const Eigen::Vector3d& p) { return {p.x(), p.y(), p.z()}; }

// The least squared distance MeshQuery's tree can return for triangle abc: CGAL's projection of
// p, and the triangle's first corner, the tree's reference point (its search starts from the
// nearest of those).
double tree_squared_distance(const K::Point_3& p, const BoundaryParts::Corners& c) {
  const K::Triangle_3 t(to_cgal(c[0]), to_cgal(c[1]), to_cgal(c[2]));
  const double projected = CGAL::squared_distance(p, K().construct_projected_point_3_object()(t, p));
  return std::min(projected, CGAL::squared_distance(p, t.vertex(0)));
}
}  // namespace

NearBoundaryQuery::NearBoundaryQuery(const DeformingQuery& hierarchy, TriMesh mesh)
    : mesh_(std::move(mesh)),
      wn_(mesh_),
      parts_(mesh_, wn_),
      shape_(hierarchy.shape(mesh_.vertices)),
      diagonal_(mesh_.diagonal()),
      decided_(new std::once_flag[mesh_.triangles.size()]),
      part_(mesh_.triangles.size()) {}

const BoundaryParts::Part& NearBoundaryQuery::part(size_t t) const {
  std::call_once(decided_[t], [&] { part_[t] = parts_.part(t); });
  return part_[t];
}

double NearBoundaryQuery::distance_below(const Eigen::Vector3d& p, double reach) const {
  // Every triangle nearer than reach, and a few more: past the rounding of the boxes' sums.
  const double bound = reach * (1 + 1e-9) + 1e-12 * diagonal_;
  thread_local std::vector<int> near;
  shape_.triangles_near(p, bound, near);
  const K::Point_3 q = to_cgal(p);
  double best = std::numeric_limits<double>::infinity();
  for (int t : near) {
    if (is_degenerate(mesh_, t, diagonal_)) continue;
    const BoundaryParts::Part& bounding = part(size_t(t));
    if (bounding.kind == BoundaryParts::Part::whole) {
      const Eigen::Vector3i& f = mesh_.triangles[size_t(t)];
      best = std::min(best, tree_squared_distance(q, {mesh_.vertices[size_t(f[0])], mesh_.vertices[size_t(f[1])],
                                                      mesh_.vertices[size_t(f[2])]}));
    }
    // MeshQuery's tree leaves degenerate pieces out too.
    for (const BoundaryParts::Corners& piece : bounding.bounding)
      if (!is_degenerate(piece[0], piece[1], piece[2], diagonal_)) best = std::min(best, tree_squared_distance(q, piece));
  }
  const double d = std::sqrt(best);
  return d < reach ? d : std::numeric_limits<double>::infinity();
}

}  // namespace spx
