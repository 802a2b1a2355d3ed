#pragma once
// Signed distances to one closed triangle mesh in many shapes (a skinned body's frames, hundreds
// of them): the hierarchy is built once on the rest and refitted to each shape in linear time,
// and inside is told by the closest point's angle-weighted pseudo-normal (Baerentzen and Aanaes
// 2005), exact for a closed, consistently oriented, edge-manifold mesh. A MeshQuery per frame
// would rebuild its trees and its winding-number expansions every time.
#include <vector>

#include "mesh/mesh.hpp"

namespace spx {

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

   private:
    friend class DeformingQuery;
    const DeformingQuery* q_ = nullptr;
    std::vector<Eigen::Vector3d> v_;
    std::vector<Eigen::AlignedBox3d> box_;              // per node
    std::vector<Eigen::Vector3d> face_n_, vertex_n_, edge_n_;  // pseudo-normals
  };
  Shape shape(std::vector<Eigen::Vector3d> vertices) const;

 private:
  struct Node {
    int first = 0, count = 0;  // triangle range in order_ (a leaf)
    int left = -1, right = -1;
  };
  int build(const std::vector<Eigen::Vector3d>& centroid, int first, int count);

  std::vector<Eigen::Vector3i> tri_;
  std::vector<std::array<int, 3>> edge_of_;  // per triangle, edge k (from corner k to k+1)
  size_t edges_ = 0;
  std::vector<int> order_;                   // triangles in tree order
  std::vector<Node> nodes_;                  // parents before children
  bool closed_ = false;
};

}  // namespace spx
