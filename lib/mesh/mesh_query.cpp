#include "mesh/mesh_query.hpp"

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Simple_cartesian.h>

#include <iterator>

#include "core/error.hpp"
#include "mesh/defects.hpp"
#include "mesh/solid_boundary.hpp"

namespace spx {

namespace {
using K = CGAL::Simple_cartesian<double>;
using Triangle = K::Triangle_3;
using Iterator = std::vector<Triangle>::const_iterator;
using Primitive = CGAL::AABB_triangle_primitive<K, Iterator>;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<K, Primitive>>;

K::Point_3 to_cgal(const Eigen::Vector3d& p) { return {p.x(), p.y(), p.z()}; }
}  // namespace

struct MeshQuery::Tree {
  std::vector<Triangle> triangles;  // non-degenerate ones only
  std::vector<int> ids;             // index into the mesh's triangles
  ::spx::Tree tree;
};

MeshQuery::MeshQuery(const TriMesh& mesh) : mesh_(mesh), wn_(mesh_), tree_(std::make_unique<Tree>()) {
  const double diag = mesh_.diagonal();
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
  tree_->tree.insert(tree_->triangles.cbegin(), tree_->triangles.cend());
  tree_->tree.accelerate_distance_queries();
}

MeshQuery::~MeshQuery() = default;

double MeshQuery::distance(const Eigen::Vector3d& p) const {
  return std::sqrt(tree_->tree.squared_distance(to_cgal(p)));
}

double MeshQuery::distance(const Eigen::Vector3d& p, const Eigen::Vector3d& hint) const {
  return std::sqrt(tree_->tree.squared_distance(to_cgal(p), to_cgal(hint)));
}

namespace {
Eigen::Vector3d corner(const Triangle& t, int k) { return {t.vertex(k).x(), t.vertex(k).y(), t.vertex(k).z()}; }
}  // namespace

ClosestPoint MeshQuery::closest(const Eigen::Vector3d& p) const {
  const auto [point, primitive] = tree_->tree.closest_point_and_primitive(to_cgal(p));
  ClosestPoint out;
  const Triangle& piece = *primitive;
  out.triangle = tree_->ids[static_cast<size_t>(primitive - tree_->triangles.cbegin())];
  const auto& f = mesh_.triangles[out.triangle];
  const Eigen::Vector3d &a = mesh_.vertices[f[0]], &b = mesh_.vertices[f[1]], &c = mesh_.vertices[f[2]];
  // Recompute in our own terms to get barycentric coordinates that match the point: on the
  // piece of the triangle that bounds, then in the whole triangle.
  out.point = corner(piece, 0) == a && corner(piece, 1) == b && corner(piece, 2) == c
                  ? closest_point_on_triangle(p, a, b, c, &out.barycentric)
                  : closest_point_on_triangle(closest_point_on_triangle(p, corner(piece, 0), corner(piece, 1), corner(piece, 2)),
                                              a, b, c, &out.barycentric);
  out.distance = (out.point - p).norm();
  out.tree_distance = std::sqrt(CGAL::squared_distance(to_cgal(p), point));
  return out;
}

ClosestPoint MeshQuery::closest_apart(const Eigen::Vector3d& p, double radius,
                                      const std::vector<Eigen::Vector3d>& corners) const {
  std::vector<Iterator> near;
  tree_->tree.all_intersected_primitives(K::Sphere_3(to_cgal(p), radius * radius), std::back_inserter(near));
  ClosestPoint out;
  out.distance = radius;
  for (Iterator t : near) {
    const Eigen::Vector3d a = corner(*t, 0), b = corner(*t, 1), c = corner(*t, 2);
    if (has_corner(corners, a, b, c)) continue;
    const Eigen::Vector3d q = closest_point_on_triangle(p, a, b, c);
    const double d = (q - p).norm();
    if (d >= out.distance) continue;
    out.point = q;
    out.distance = d;
    out.triangle = tree_->ids[static_cast<size_t>(t - tree_->triangles.cbegin())];
  }
  return out;
}

double MeshQuery::signed_distance(const Eigen::Vector3d& p) const {
  const double d = distance(p);
  return inside(p) ? -d : d;
}

}  // namespace spx
