#include "sdf/surface_layer.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include <cmath>

#include "mesh/mesh_query.hpp"
#include "mesh/normals.hpp"

namespace spx {

void rasterize_surface_layer(const TriMesh& mesh, const GridShape& shape, GridVector<float>& dist,
                             GridVector<int32_t>& closest) {
  const double h = shape.voxel_size;
  struct Box {
    int from[3], to[3];
  };
  std::vector<Box> boxes(mesh.triangles.size());
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& f = mesh.triangles[t];
    const Eigen::Vector3d &a = mesh.vertices[f[0]], &b = mesh.vertices[f[1]], &c = mesh.vertices[f[2]];
    const Eigen::Vector3d lo = a.cwiseMin(b).cwiseMin(c) / h, hi = a.cwiseMax(b).cwiseMax(c) / h;
    for (int axis = 0; axis < 3; ++axis) {
      boxes[t].from[axis] = std::max(0, int(std::ceil(lo[axis] - 1)) - shape.origin[axis]);
      boxes[t].to[axis] = std::min(shape.dims[axis] - 1, int(std::floor(hi[axis] + 1)) - shape.origin[axis]);
    }
  }
  // Keeps the nearest triangle per voxel, the lowest index on ties: the result does not depend
  // on the order in which triangles arrive. Voxels of x-planes from..to only.
  auto raster = [&](size_t t, int from_x, int to_x) {
    const auto& f = mesh.triangles[t];
    const Eigen::Vector3d &a = mesh.vertices[f[0]], &b = mesh.vertices[f[1]], &c = mesh.vertices[f[2]];
    const Box& box = boxes[t];
    // A voxel farther than h from the triangle's plane is farther from the triangle: skipped
    // before the closest point (the margin keeps every voxel the exact test would keep).
    const Eigen::Vector3d cross = (b - a).cross(c - a);
    const Eigen::Vector3d n = cross.norm() > 0 ? Eigen::Vector3d(cross / cross.norm()) : Eigen::Vector3d::Zero();
    const double reach2 = h * h * (1 + 1e-9);
    for (int i = from_x; i <= to_x; ++i)
      for (int j = box.from[1]; j <= box.to[1]; ++j)
        for (int k = box.from[2]; k <= box.to[2]; ++k) {
          const Eigen::Vector3d p = shape.world(i, j, k);
          const double plane = n.dot(p - a);
          if (plane * plane > reach2) continue;
          const double d2 = (closest_point_on_triangle(p, a, b, c) - p).squaredNorm();
          if (d2 > h * h) continue;
          const float d = float(std::sqrt(d2));
          const size_t idx = shape.index(i, j, k);
          if (closest[idx] < 0 || d < dist[idx] || (d == dist[idx] && int32_t(t) < closest[idx])) {
            dist[idx] = d;
            closest[idx] = int32_t(t);
          }
        }
  };
  // Slabs of kSlab x-planes: a triangle narrower than a slab, filed under the slab of its first
  // plane, writes within that slab and the next. So the even slabs run in parallel without
  // locks, then the odd ones. Wider triangles (rare in meshes fine enough to need speed) go
  // last, one at a time, parallel over their planes.
  constexpr int kSlab = 8;
  const int slabs = (shape.dims.x() + kSlab - 1) / kSlab;
  std::vector<std::vector<int32_t>> in_slab(static_cast<size_t>(slabs));
  std::vector<int32_t> wide;
  for (size_t t = 0; t < boxes.size(); ++t) {
    const Box& box = boxes[t];
    if (box.from[0] > box.to[0] || box.from[1] > box.to[1] || box.from[2] > box.to[2]) continue;
    if (box.to[0] - box.from[0] < kSlab) in_slab[size_t(box.from[0] / kSlab)].push_back(int32_t(t));
    else wide.push_back(int32_t(t));
  }
  for (int parity = 0; parity < 2; ++parity)
    tbb::parallel_for(tbb::blocked_range<int>(0, (slabs + 1 - parity) / 2), [&](const tbb::blocked_range<int>& r) {
      for (int n = r.begin(); n != r.end(); ++n)
        for (int32_t t : in_slab[size_t(2 * n + parity)]) raster(size_t(t), boxes[size_t(t)].from[0], boxes[size_t(t)].to[0]);
    });
  for (int32_t t : wide)
    tbb::parallel_for(tbb::blocked_range<int>(boxes[size_t(t)].from[0], boxes[size_t(t)].to[0] + 1),
                      [&](const tbb::blocked_range<int>& r) { raster(size_t(t), r.begin(), r.end() - 1); });
}

PseudoNormals::PseudoNormals(const TriMesh& mesh)
    : face_(face_normals(mesh)), vertex_(angle_weighted_normals(mesh, face_)) {
  const size_t count = mesh.triangles.size();
  // Edge k of triangle t (corner k to k + 1) is slot 3t + k. Sorted by undirected edge, then
  // slot, the faces of each edge sit side by side, in triangle order.
  std::vector<std::pair<uint64_t, uint32_t>> half(3 * count);
  for (size_t t = 0; t < count; ++t)
    for (int k = 0; k < 3; ++k)
      half[3 * t + size_t(k)] = {edge_key(mesh.triangles[t][k], mesh.triangles[t][(k + 1) % 3]), uint32_t(3 * t + size_t(k))};
  tbb::parallel_sort(half.begin(), half.end());
  edge_.resize(3 * count);
  for (size_t i = 0; i < half.size();) {
    size_t j = i;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (; j < half.size() && half[j].first == half[i].first; ++j) sum += face_[half[j].second / 3];
    for (; i < j; ++i) edge_[half[i].second] = sum;
  }
}

int PseudoNormals::side(const TriMesh& mesh, int32_t triangle, const Eigen::Vector3d& p) const {
  const auto& f = mesh.triangles[size_t(triangle)];
  Eigen::Vector3d bary;
  const Eigen::Vector3d c = closest_point_on_triangle(p, mesh.vertices[f[0]], mesh.vertices[f[1]], mesh.vertices[f[2]], &bary);
  const int zeros = (bary[0] == 0) + (bary[1] == 0) + (bary[2] == 0);
  Eigen::Vector3d n;
  if (zeros >= 2) {  // a corner: the one with weight 1
    const int corner = bary[0] != 0 ? 0 : bary[1] != 0 ? 1 : 2;
    n = vertex_[size_t(f[corner])];
  } else if (zeros == 1) {  // the edge opposite the zero weight
    const int opposite = bary[0] == 0 ? 0 : bary[1] == 0 ? 1 : 2;
    n = edge_[3 * size_t(triangle) + size_t((opposite + 1) % 3)];
  } else {
    n = face_[size_t(triangle)];
  }
  const double along = (p - c).dot(n), norms = (p - c).norm() * n.norm();
  if (!(std::abs(along) >= 0.2 * norms) || norms == 0) return 0;
  return along < 0 ? -1 : 1;
}

}  // namespace spx
