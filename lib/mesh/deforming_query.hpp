#pragma once
// Signed distances to one closed triangle mesh in many shapes (a skinned body's frames, hundreds
// of them): the hierarchy is built once on the rest and refitted to each shape in linear time,
// and inside is told by the closest point's angle-weighted pseudo-normal (Baerentzen and Aanaes
// 2005), exact for a closed, consistently oriented, edge-manifold mesh. A MeshQuery per frame
// would rebuild its trees and its winding-number expansions every time.
#include <array>
#include <optional>
#include <vector>

#include "mesh/mesh.hpp"

namespace spx {

// A triangle's corners less a point: the point at the origin.
using Corners = std::array<Eigen::Vector3d, 3>;
// The distance from the origin to the triangle.
double distance_to_origin(const Corners& corners);
// At most the least distance from the origin to the triangle as its corners go in straight lines
// from `from` to `to` (each the same share of its way at once), the ends `from_distance` and
// `to_distance` away: every point of the step is within s D of where it starts and (1 - s) D of
// where it ends, D the farthest a corner goes, so at least min(from, to) - D / 2 from the origin.
double least_distance_over_step(const Corners& from, double from_distance, const Corners& to, double to_distance);

class DeformingQuery {
 public:
  explicit DeformingQuery(const TriMesh& rest);
  // Watertight (find_defects): every edge shared by exactly two triangles crossing it in
  // opposite directions, so the pseudo-normal's sign is exact. Otherwise shapes must not be asked.
  bool closed() const { return closed_; }

  // The mesh with `vertices` (one per rest vertex) for its triangles.
  class Shape {
   public:
    // Negative inside, |value| the exact distance.
    double signed_distance(const Eigen::Vector3d& p) const;
    // The same where some surface point is nearer than `bound`, else +infinity: the search skips
    // every box at `bound` or farther, which is most of them for a point deep inside.
    double signed_distance_within(const Eigen::Vector3d& p, double bound) const;
    // Whether some surface point is nearer to p than `bound`: the bounded search, stopped at the
    // first triangle found.
    bool nearer_than(const Eigen::Vector3d& p, double bound) const;
    // Winding number > 1/2, as the exact sum of solid angles says (winding_number_exact) but
    // counted along a ray through the hierarchy: the triangles it crosses, +1 leaving through a
    // front face, -1 entering. Where parts pass through each other the count still says inside.
    // A ray that grazes an edge is cast again another way, and after a few, the exact sum decides.
    bool inside(const Eigen::Vector3d& p) const;
    // Every triangle whose box comes nearer to p than `bound` (its index in the rest's list, in
    // no set order): a superset of those nearer than it, for a caller that decides them itself.
    void triangles_near(const Eigen::Vector3d& p, double bound, std::vector<int>& found) const;
    // With `inflation` (swept()), searches near one another entering the tree once: `leaves_near`
    // gives the leaves whose box, grown by their vertices' largest inflation, comes within reach
    // of `region`. Then for a ball p +- bound inside `region` (the point p where the bound is
    // negative: inflation alone reaches it), inflated_triangles_nearer_than
    // puts each triangle nearer to p than `bound` plus its vertices' largest inflation (its index
    // in the rest's list) into `found`, in no set order; false, with `found` incomplete, once
    // there are more than `most` (with `most` 0, at the first). Where each vertex may move
    // anywhere within its inflation, a triangle not found stays at least `bound` from p in every
    // shape of the sweep.
    void leaves_near(const Eigen::AlignedBox3d& region, std::vector<int>& leaves) const;
    bool inflated_triangles_nearer_than(const Eigen::Vector3d& p, double bound, size_t most, std::vector<int>& found,
                                        const std::vector<int>& leaves) const;

   private:
    friend class DeformingQuery;
    // The signed count of crossings along p + s dir (s > 0); nullopt where the ray grazes an
    // edge or a triangle's plane, and the count could be off by one.
    std::optional<int> crossings(const Eigen::Vector3d& p, const Eigen::Vector3d& dir) const;
    template <class Leaf>
    void search(const Eigen::Vector3d& p, double& best, Leaf&& leaf) const;
    // Node n's vertices' largest inflation (swept(): kept after the vertices' own).
    double grow(int n) const;
    // Whether node n's box, grown by its largest inflation plus `bound`, reaches p.
    bool may_reach(int n, const Eigen::Vector3d& p, double bound) const;
    // Leaf n's triangles nearer to p than `bound` plus their inflation, into `found`; false once
    // there are more than `most`.
    bool add_inflated_near(int n, const Eigen::Vector3d& p, double bound, size_t most, std::vector<int>& found) const;
    const DeformingQuery* q_ = nullptr;
    std::vector<Eigen::Vector3d> v_;
    std::vector<Eigen::AlignedBox3d> box_;  // per node
    std::vector<double> inflation_;         // swept(): per vertex, then per node its largest
    // Pseudo-normals, of the closest feature only (most of a shape's features are never closest).
    Eigen::Vector3d face_normal(int t) const;
    Eigen::Vector3d vertex_normal(int v) const;
  };
  Shape shape(std::vector<Eigen::Vector3d> vertices) const;
  // The shape, each vertex v free to move within inflation[v] of vertices[v]: for
  // inflated_triangles_nearer_than alone.
  Shape swept(std::vector<Eigen::Vector3d> vertices, std::vector<double> inflation) const;

 private:
  struct Node {
    int first = 0, count = 0;  // triangle range in order_ (a leaf)
    int left = -1, right = -1;
  };
  int build(const std::vector<Eigen::Vector3d>& centroid, int first, int count);

  std::vector<Eigen::Vector3i> tri_;
  std::vector<std::array<int, 3>> edge_of_;  // per triangle, edge k (from corner k to k+1)
  std::vector<std::array<int, 2>> edge_tris_;  // per edge, its two triangles
  std::vector<int> corner_start_;              // per vertex + 1, offsets into corners_
  std::vector<std::pair<int, int>> corners_;   // (triangle, corner) at each vertex
  std::vector<int> order_;                   // triangles in tree order
  std::vector<Node> nodes_;                  // parents before children
  bool closed_ = false;
};

// Inside a closed mesh (winding number > 1/2) by a ray's signed crossings through its hierarchy:
// the winding number off the surface, in a fraction of the time of its expansions. Unknown
// (nullopt) within 1e-9 of the diagonal of the surface, where a ray from a face counts it or not
// by a rounding, and everywhere for a mesh that is not closed (or with `use` false): there the
// caller asks the winding number. `mesh` need not outlive it.
class RayInside {
 public:
  explicit RayInside(const TriMesh& mesh, bool use = true);
  std::optional<bool> operator()(const Eigen::Vector3d& p) const;

 private:
  DeformingQuery rays_;
  std::optional<DeformingQuery::Shape> shape_;
  double on_surface_ = 0;
};

}  // namespace spx
