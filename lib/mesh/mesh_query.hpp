#pragma once
// Exact closest points (CGAL AABB tree) and robust inside tests (winding number) on one mesh.
// Distances and closest points are to the solid's boundary: walls inside the solid (where
// parts overlap; mesh/solid_boundary.hpp) are left out, since a sphere may cross them.
#include <memory>
#include <vector>

#include "mesh/deforming_query.hpp"
#include "mesh/mesh.hpp"
#include "mesh/solid_boundary.hpp"
#include "mesh/winding_number.hpp"

namespace spx {

struct ClosestPoint {
  Eigen::Vector3d point;
  Eigen::Vector3d barycentric;  // of `point` in triangle `triangle`
  int triangle = -1;
  double distance = 0;
  // The distance as MeshQuery::distance gives it, to the bit (the tree's own closest point, of
  // which `point` is a recomputation): a caller that needs both asks once.
  double tree_distance = 0;
  int piece = -1;  // the tree's primitive (a triangle, or its piece on the solid's boundary)
};

// Whether one of `corners` is a, b or c (exactly): a triangle of a point's own neighbourhood.
inline bool has_corner(const std::vector<Eigen::Vector3d>& corners, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                       const Eigen::Vector3d& c) {
  for (const Eigen::Vector3d& k : corners)
    if (k == a || k == b || k == c) return true;
  return false;
}

class MeshQuery {
 public:
  explicit MeshQuery(const TriMesh& mesh);
  ~MeshQuery();
  MeshQuery(const MeshQuery&) = delete;
  MeshQuery& operator=(const MeshQuery&) = delete;

  const TriMesh& mesh() const { return mesh_; }
  // Triangles left out as walls inside the solid, and those kept in pieces (solid_boundary).
  size_t internal_walls() const { return boundary_.internal; }
  size_t split_triangles() const { return boundary_.split; }
  // The solid's surface (solid_surface): the mesh less its walls inside the solid.
  const TriMesh& surface() const { return boundary_.whole() ? mesh_ : surface_; }
  // The solid's boundary (solid_boundary), for a field of the same mesh (build_sdf).
  const SolidBoundary& boundary() const { return boundary_; }
  double distance(const Eigen::Vector3d& p) const;
  // The same, faster when `hint` is a surface point near the closest one.
  double distance(const Eigen::Vector3d& p, const Eigen::Vector3d& hint) const;
  ClosestPoint closest(const Eigen::Vector3d& p) const;
  // The same, searched from `hint`, a closest point of this query asked for a point near p: its
  // distance bounds the search from the start, so that far fewer boxes are opened. The tree
  // returns the same primitive and point as without it (but where two are equally near).
  ClosestPoint closest(const Eigen::Vector3d& p, const ClosestPoint& hint) const;
  // The closest point to p nearer than `radius` on a triangle that has none of `corners` as a
  // corner (triangle -1 when there is none): past a surface point's own neighbourhood. Point,
  // triangle and distance only (no barycentric weights).
  ClosestPoint closest_apart(const Eigen::Vector3d& p, double radius, const std::vector<Eigen::Vector3d>& corners) const;
  double winding_number(const Eigen::Vector3d& p) const { return wn_(p); }
  // Whether the winding number's hierarchy has been built (it is on the first question).
  bool winding_number_built() const { return wn_.built(); }
  bool inside(const Eigen::Vector3d& p) const { return inside_by_ ? inside_by_->inside(p) : wn_.inside(p); }
  // inside() told by `shape` from now on: a closed mesh's refitted hierarchy (the same mesh), whose
  // ray count is the winding number off the surface, so that the winding number's hierarchy is
  // never built. Set before the query is shared between threads.
  void tell_inside_by(const DeformingQuery::Shape* shape) { inside_by_ = shape; }
  // Negative inside (winding number > 1/2).
  double signed_distance(const Eigen::Vector3d& p) const;
  // Whether the solid lies beside surface point p on either side (probed kWallProbe of the
  // diagonal along `normal` and against it): not on an open or inward-facing part that encloses
  // nothing there, where no inscribed sphere touches p at any resolution.
  bool solid_beside(const Eigen::Vector3d& p, const Eigen::Vector3d& normal) const;

 private:
  struct Tree;
  // The closest point as the tree found it (its primitive and point) in the caller's terms.
  ClosestPoint closest_on(const Eigen::Vector3d& p, int piece, const Eigen::Vector3d& tree_point) const;
  TriMesh mesh_;
  // Built on the first inside() or winding number asked: a closed pose whose inside is told by
  // the refitted hierarchy's ray count (PoseSolid) never asks, nor does the boundary of a single
  // closed surface, and on a dense mesh it is the query's largest part.
  WindingNumber wn_;
  const DeformingQuery::Shape* inside_by_ = nullptr;
  std::unique_ptr<Tree> tree_;
  SolidBoundary boundary_;
  TriMesh surface_;  // where the boundary is not whole
  double probe_ = 0;  // solid_beside's step: kWallProbe of the diagonal
};

// The closest point of triangle abc to p, with its barycentric weights on request (Ericson,
// Real-Time Collision Detection, 5.1.5). Inline: the SDF calls it tens of millions of times.
inline Eigen::Vector3d closest_point_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                                 const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                                                 Eigen::Vector3d* bary = nullptr) {
  auto out = [&](double u, double v, double w) {
    if (bary) *bary = Eigen::Vector3d(u, v, w);
    return Eigen::Vector3d(u * a + v * b + w * c);
  };
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return out(1, 0, 0);
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return out(0, 1, 0);
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    const double v = d1 / (d1 - d3);
    return out(1 - v, v, 0);
  }
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return out(0, 0, 1);
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    const double w = d2 / (d2 - d6);
    return out(1 - w, 0, w);
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return out(0, 1 - w, w);
  }
  const double denom = 1.0 / (va + vb + vc);
  const double v = vb * denom, w = vc * denom;
  return out(1 - v - w, v, w);
}

}  // namespace spx
