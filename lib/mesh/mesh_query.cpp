#include "mesh/mesh_query.hpp"

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Simple_cartesian.h>

#include <iterator>
#include <optional>

#include "core/error.hpp"
#include "mesh/defects.hpp"
#include "mesh/solid_boundary.hpp"

namespace spx {

namespace {
using K = CGAL::Simple_cartesian<double>;
using Triangle = K::Triangle_3;
using Iterator = std::vector<Triangle>::const_iterator;
using Primitive = CGAL::AABB_triangle_primitive<K, Iterator>;

Eigen::Vector3d corner(const Triangle& t, int k) { return {t.vertex(k).x(), t.vertex(k).y(), t.vertex(k).z()}; }

// What the leaf test needs of a triangle, computed once: its box, the size its margin scales
// with, and its plane (unit normal and offset) with the plane distance's error bound per unit of
// coordinate size (large for a sliver, whose normal is ill-conditioned).
struct LeafTriangle {
  Eigen::Vector3d lo, hi, normal = Eigen::Vector3d::Zero();
  double offset = 0, size = 0, plane_error = 0;
};

LeafTriangle leaf_triangle(const Triangle& t) {
  const Eigen::Vector3d a = corner(t, 0), b = corner(t, 1), c = corner(t, 2);
  LeafTriangle out;
  out.lo = a.cwiseMin(b).cwiseMin(c);
  out.hi = a.cwiseMax(b).cwiseMax(c);
  out.size = a.lpNorm<Eigen::Infinity>() + 2 * (b - a).lpNorm<Eigen::Infinity>() + 2 * (c - a).lpNorm<Eigen::Infinity>();
  const Eigen::Vector3d cross = (b - a).cross(c - a);
  const double area2 = cross.norm(), edges = (b - a).norm() * (c - a).norm();
  // The normal's direction is good to about a rounding over the sine of the corner's angle. Far
  // under a millionth (a sliver) the plane tells nothing: a zero normal never rules a leaf out.
  const double sine = edges > 0 ? area2 / edges : 0;
  if (!(sine > 1e-6)) return out;
  out.normal = cross / area2;
  out.offset = out.normal.dot(a);
  out.plane_error = 1e-12 / sine;
  return out;
}

// Whether triangle t is farther from q than sqrt(far2) by more than a margin far above each
// computation's rounding: by its box or its plane alone (beyond_box_or_plane), or else also by its
// closest point (surely_farther); in squares, no square root on a leaf. The margins scale with
// `scale`, the query's largest coordinate plus the triangle's size (leaf_scale): a billionth of
// it, and of the distance itself: (far + m)^2 <= far2 (1 + e) + m^2 (1 + 1/e), e = 1e-6.
double leaf_scale(const Eigen::Vector3d& q, const LeafTriangle& leaf) { return q.lpNorm<Eigen::Infinity>() + leaf.size; }
double margined(double far2, double scale) {
  const double m = 1e-9 * scale;
  return far2 * ((1 + 3e-9) * (1 + 1e-6)) + m * m * (1 + 1e6);
}
bool beyond_box_or_plane(const Eigen::Vector3d& q, const LeafTriangle& leaf, double limit, double scale) {
  const double box2 = ((leaf.lo - q).cwiseMax(q - leaf.hi)).cwiseMax(0.0).squaredNorm();
  if (box2 > limit) return true;
  const double plane = leaf.normal.dot(q) - leaf.offset, slack = leaf.plane_error * scale;
  return plane * plane > limit * (1 + 1e-6) + slack * slack * (1 + 1e6);
}
bool surely_farther(const Eigen::Vector3d& q, const Triangle& t, const LeafTriangle& leaf, double far2) {
  const double scale = leaf_scale(q, leaf), limit = margined(far2, scale);
  if (beyond_box_or_plane(q, leaf, limit, scale)) return true;
  return (closest_point_on_triangle(q, corner(t, 0), corner(t, 1), corner(t, 2)) - q).squaredNorm() > limit;
}

// CGAL's traits with a cheaper leaf test. The tree's closest-point search asks each leaf
// triangle for its projection of the query and keeps it when nearer than the best so far; most
// leaves it visits are farther. Those are told by the triangle's box, its plane, or else the
// closed-form closest point (Ericson), in squares, in a few dozen flops, and only a triangle that
// may be nearer (within a margin far above each computation's rounding) is projected by CGAL's
// own construction. So the search returns what CGAL's traits return, bit for bit, in a fraction
// of the time. The plane tells most of them near an inscribed ball's centre: there the ball
// touches the surface, every box around the touching point reaches into it, but the planes of
// the triangles there pass at least as far as the point touched.
class Traits : public CGAL::AABB_traits<K, Primitive> {
 public:
  Traits() = default;
  Traits(const Triangle* first, const LeafTriangle* leaves) : first_(first), leaves_(leaves) {}
  class Closest_point {
   public:
    Closest_point(const Triangle* first, const LeafTriangle* leaves) : first_(first), leaves_(leaves) {}
    K::Point_3 operator()(const K::Point_3& p, const Primitive& primitive, const K::Point_3& bound) const {
      const Triangle& t = *primitive.id();
      const Eigen::Vector3d q(p.x(), p.y(), p.z());
      if (surely_farther(q, t, leaves_[&t - first_], CGAL::squared_distance(p, bound))) return bound;
      const K::Point_3 projected = K().construct_projected_point_3_object()(t, p);
      return K().compare_distance_3_object()(p, projected, bound) == CGAL::LARGER ? bound : projected;
    }

   private:
    const Triangle* first_;
    const LeafTriangle* leaves_;
  };
  Closest_point closest_point_object() const { return {first_, leaves_}; }
  // Whether a box may hold a point nearer than `bound`: CGAL's sphere-box test (its sums in its
  // order, so the same answer to the bit) without building the sphere.
  class Compare_distance {
   public:
    CGAL::Comparison_result operator()(const K::Point_3& p, const CGAL::Bbox_3& box, const K::Point_3& bound) const {
      const double squared_radius = CGAL::squared_distance(p, bound);
      auto gap = [](double c, double lo, double hi) {
        if (c < lo) return (lo - c) * (lo - c);
        if (c > hi) return (c - hi) * (c - hi);
        return 0.0;
      };
      double distance = gap(p.x(), box.xmin(), box.xmax());
      distance += gap(p.y(), box.ymin(), box.ymax());
      distance += gap(p.z(), box.zmin(), box.zmax());
      return distance <= squared_radius ? CGAL::SMALLER : CGAL::LARGER;
    }
  };
  Compare_distance compare_distance_object() const { return {}; }

 private:
  const Triangle* first_ = nullptr;
  const LeafTriangle* leaves_ = nullptr;
};
using Tree = CGAL::AABB_tree<Traits>;

K::Point_3 to_cgal(const Eigen::Vector3d& p) { return {p.x(), p.y(), p.z()}; }

// closest_apart's search, as CGAL's traversal asks it: the nearer box first, every box and
// triangle farther than the nearest point so far (at first the radius) left, and the triangles
// with one of the corners skipped.
class ApartSearch {
 public:
  using Priority = double;
  ApartSearch(const Eigen::Vector3d& p, double radius, const std::vector<Eigen::Vector3d>& corners,
              const Triangle* first, const LeafTriangle* leaves)
      : p_(p), corners_(corners), best2_(radius * radius), first_(first), leaves_(leaves) {}
  bool go_further() const { return true; }
  void intersection(const K::Point_3&, const Primitive& primitive) {
    const Triangle& t = *primitive.id();
    // Told by box or plane first: only a triangle within the margin of the nearest so far may
    // be nearer by the closed form below.
    const LeafTriangle& leaf = leaves_[&t - first_];
    const double scale = leaf_scale(p_, leaf);
    if (beyond_box_or_plane(p_, leaf, margined(best2_, scale), scale)) return;
    const Eigen::Vector3d a = corner(t, 0), b = corner(t, 1), c = corner(t, 2);
    if (has_corner(corners_, a, b, c)) return;
    const Eigen::Vector3d q = closest_point_on_triangle(p_, a, b, c);
    const double d2 = (q - p_).squaredNorm();
    if (d2 >= best2_) return;
    best2_ = d2;
    point_ = q;
    found_ = primitive.id();
    any_ = true;
  }
  template <class Node>
  bool do_intersect(const K::Point_3&, const Node& node) const {
    return box2(node.bbox()) < best2_;
  }
  template <class Node>
  std::pair<bool, Priority> do_intersect_with_priority(const K::Point_3&, const Node& node) const {
    const double d2 = box2(node.bbox());
    return {d2 < best2_, -d2};
  }
  bool any() const { return any_; }
  Iterator found() const { return found_; }
  const Eigen::Vector3d& point() const { return point_; }

 private:
  double box2(const CGAL::Bbox_3& box) const {
    const Eigen::Vector3d lo(box.xmin(), box.ymin(), box.zmin()), hi(box.xmax(), box.ymax(), box.zmax());
    return (lo - p_).cwiseMax(p_ - hi).cwiseMax(0.0).squaredNorm();
  }
  Eigen::Vector3d p_, point_;
  const std::vector<Eigen::Vector3d>& corners_;
  double best2_;
  const Triangle* first_;
  const LeafTriangle* leaves_;
  Iterator found_;
  bool any_ = false;
};
}  // namespace

struct MeshQuery::Tree {
  std::vector<Triangle> triangles;  // non-degenerate ones only
  std::vector<int> ids;             // index into the mesh's triangles
  std::vector<LeafTriangle> leaves;  // the leaf test's data, one per triangle
  std::optional<::spx::Tree> tree;   // made once the triangles are in place
};

MeshQuery::MeshQuery(const TriMesh& mesh)
    : mesh_(mesh), wn_(WindingNumber::on_first_use(mesh_)), tree_(std::make_unique<Tree>()) {
  const double diag = mesh_.diagonal();
  probe_ = kWallProbe * diag;
  boundary_ = solid_boundary(mesh_, wn_);
  const SolidBoundary& boundary = boundary_;
  const TriMesh& kept = boundary.whole() ? mesh_ : boundary.mesh;
  for (size_t t = 0; t < kept.triangles.size(); ++t) {
    if (is_degenerate(kept, static_cast<int>(t), diag)) continue;
    const auto& f = kept.triangles[t];
    tree_->triangles.emplace_back(to_cgal(kept.vertices[f[0]]), to_cgal(kept.vertices[f[1]]), to_cgal(kept.vertices[f[2]]));
    tree_->ids.push_back(boundary.whole() ? static_cast<int>(t) : boundary.source[t]);
  }
  if (!boundary.whole()) surface_ = solid_surface(mesh_, boundary);
  if (tree_->triangles.empty()) throw Error(ExitCode::bad_input, "", "mesh has no triangle with a non-zero area");
  for (const Triangle& t : tree_->triangles) tree_->leaves.push_back(leaf_triangle(t));
  tree_->tree.emplace(Traits(tree_->triangles.data(), tree_->leaves.data()));
  tree_->tree->insert(tree_->triangles.cbegin(), tree_->triangles.cend());
  tree_->tree->accelerate_distance_queries();
}

MeshQuery::~MeshQuery() = default;

double MeshQuery::distance(const Eigen::Vector3d& p) const {
  return std::sqrt(tree_->tree->squared_distance(to_cgal(p)));
}

double MeshQuery::distance(const Eigen::Vector3d& p, const Eigen::Vector3d& hint) const {
  return std::sqrt(tree_->tree->squared_distance(to_cgal(p), to_cgal(hint)));
}

ClosestPoint MeshQuery::closest(const Eigen::Vector3d& p) const {
  const auto [point, primitive] = tree_->tree->closest_point_and_primitive(to_cgal(p));
  return closest_on(p, static_cast<int>(primitive - tree_->triangles.cbegin()), {point.x(), point.y(), point.z()});
}

ClosestPoint MeshQuery::closest(const Eigen::Vector3d& p, const ClosestPoint& hint) const {
  if (hint.piece < 0) return closest(p);
  const Iterator primitive = tree_->triangles.cbegin() + hint.piece;
  // A point of the piece itself (hint.point lies on the whole triangle).
  const Eigen::Vector3d on = closest_point_on_triangle(hint.point, corner(*primitive, 0), corner(*primitive, 1),
                                                        corner(*primitive, 2));
  const auto [point, found] = tree_->tree->closest_point_and_primitive(to_cgal(p), {to_cgal(on), primitive});
  return closest_on(p, static_cast<int>(found - tree_->triangles.cbegin()), {point.x(), point.y(), point.z()});
}

ClosestPoint MeshQuery::closest_on(const Eigen::Vector3d& p, int piece_index, const Eigen::Vector3d& tree_point) const {
  ClosestPoint out;
  out.piece = piece_index;
  const Triangle& piece = tree_->triangles[static_cast<size_t>(piece_index)];
  out.triangle = tree_->ids[static_cast<size_t>(piece_index)];
  const auto& f = mesh_.triangles[out.triangle];
  const Eigen::Vector3d &a = mesh_.vertices[f[0]], &b = mesh_.vertices[f[1]], &c = mesh_.vertices[f[2]];
  // Recompute in our own terms to get barycentric coordinates that match the point: on the
  // piece of the triangle that bounds, then in the whole triangle.
  out.point = corner(piece, 0) == a && corner(piece, 1) == b && corner(piece, 2) == c
                  ? closest_point_on_triangle(p, a, b, c, &out.barycentric)
                  : closest_point_on_triangle(closest_point_on_triangle(p, corner(piece, 0), corner(piece, 1), corner(piece, 2)),
                                              a, b, c, &out.barycentric);
  out.distance = (out.point - p).norm();
  out.tree_distance = std::sqrt(CGAL::squared_distance(to_cgal(p), to_cgal(tree_point)));
  return out;
}

ClosestPoint MeshQuery::closest_apart(const Eigen::Vector3d& p, double radius,
                                      const std::vector<Eigen::Vector3d>& corners) const {
  ClosestPoint out;
  out.distance = radius;
  ApartSearch search(p, radius, corners, tree_->triangles.data(), tree_->leaves.data());
  tree_->tree->traversal_with_priority(to_cgal(p), search);
  if (!search.any()) return out;
  out.point = search.point();
  out.distance = (out.point - p).norm();
  out.piece = static_cast<int>(search.found() - tree_->triangles.cbegin());
  out.triangle = tree_->ids[static_cast<size_t>(out.piece)];
  return out;
}

double MeshQuery::signed_distance(const Eigen::Vector3d& p) const {
  const double d = distance(p);
  return inside(p) ? -d : d;
}

bool MeshQuery::solid_beside(const Eigen::Vector3d& p, const Eigen::Vector3d& normal) const {
  return inside(p - probe_ * normal) || inside(p + probe_ * normal);
}

}  // namespace spx
