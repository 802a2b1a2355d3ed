#pragma once
// MeshQuery's inside test and distance, to the bit, for a mesh asked at a few points only (a
// clip's times, each skinned afresh): the solid's boundary (solid_boundary) is decided only for
// the triangles a query comes near, where MeshQuery decides it for every triangle first (most of
// its cost on a body of open parts).
#include <memory>
#include <mutex>
#include <vector>

#include "mesh/deforming_query.hpp"
#include "mesh/mesh.hpp"
#include "mesh/solid_boundary.hpp"
#include "mesh/winding_number.hpp"

namespace spx {

class NearBoundaryQuery {
 public:
  // `hierarchy`: a DeformingQuery of `mesh`'s triangles, refitted here to its vertices.
  NearBoundaryQuery(const DeformingQuery& hierarchy, TriMesh mesh);
  NearBoundaryQuery(const NearBoundaryQuery&) = delete;
  NearBoundaryQuery& operator=(const NearBoundaryQuery&) = delete;

  bool inside(const Eigen::Vector3d& p) const { return wn_.inside(p); }
  // MeshQuery(mesh).distance(p) where it is below `reach`; +infinity where it is not. Safe to ask
  // from several threads.
  double distance_below(const Eigen::Vector3d& p, double reach) const;

 private:
  const BoundaryParts::Part& part(size_t t) const;
  TriMesh mesh_;
  WindingNumber wn_;
  BoundaryParts parts_;
  DeformingQuery::Shape shape_;
  double diagonal_;
  std::unique_ptr<std::once_flag[]> decided_;
  mutable std::vector<BoundaryParts::Part> part_;
};

}  // namespace spx
