#pragma once
// The voxels next to a mesh's surface: exact distances and closest triangles, and the sign
// there for closed surfaces.
#include <cstdint>
#include <vector>

#include "mesh/mesh.hpp"
#include "io/dense_field.hpp"

namespace spx {

// For every voxel whose centre lies within one voxel of the mesh: the exact distance and the
// closest triangle (the lowest index on ties, so the result does not depend on threads).
// `closest` must start at -1 everywhere; other voxels are left as they are. Each triangle
// visits the voxels of its bounding box grown by one voxel, in parallel.
void rasterize_surface_layer(const TriMesh& mesh, const GridShape& shape, GridVector<float>& dist,
                             GridVector<int32_t>& closest);

// Angle-weighted pseudo-normals (Baerentzen & Aanaes 2005): for a closed, manifold,
// consistently oriented surface, the side of a point is the sign of (p - c) . N, where c is
// the closest point and N the pseudo-normal of the face, edge or vertex c lies on.
class PseudoNormals {
 public:
  explicit PseudoNormals(const TriMesh& mesh);
  // The side of p, given the triangle closest to p: -1 inside, +1 outside, 0 when p - c is
  // nearly tangent to the pseudo-normal (|cos| < 0.2): there a triangle that is closest only
  // up to rounding can give the wrong side, and the caller should ask the winding number.
  int side(const TriMesh& mesh, int32_t triangle, const Eigen::Vector3d& p) const;

 private:
  static uint64_t edge_key(int a, int b) {
    return a < b ? (uint64_t(uint32_t(a)) << 32) | uint32_t(b) : (uint64_t(uint32_t(b)) << 32) | uint32_t(a);
  }
  std::vector<Eigen::Vector3d> face_, vertex_;
  std::vector<Eigen::Vector3d> edge_;  // slot 3t + k: the sum of the normals of the faces on edge k of triangle t
};

}  // namespace spx
