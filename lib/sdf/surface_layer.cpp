#include "sdf/surface_layer.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <atomic>
#include <cmath>
#include <cstring>
#include <memory>

#include "mesh/mesh_query.hpp"

namespace spx {

void rasterize_surface_layer(const TriMesh& mesh, const GridShape& shape, std::vector<float>& dist,
                             std::vector<int32_t>& closest) {
  const size_t total = shape.count();
  const double h = shape.voxel_size;
  // (distance bits, triangle) in one word: non-negative floats order like their bit patterns,
  // so one atomic minimum keeps the nearest triangle and, on ties, the lowest index.
  constexpr uint64_t kEmpty = ~uint64_t(0);
  std::unique_ptr<std::atomic<uint64_t>[]> best(new std::atomic<uint64_t>[total]);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, total, 1 << 16), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t i = r.begin(); i != r.end(); ++i) best[i].store(kEmpty, std::memory_order_relaxed);
  });
  tbb::parallel_for(tbb::blocked_range<size_t>(0, mesh.triangles.size(), 256), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t t = r.begin(); t != r.end(); ++t) {
      const auto& f = mesh.triangles[t];
      const Eigen::Vector3d &a = mesh.vertices[f[0]], &b = mesh.vertices[f[1]], &c = mesh.vertices[f[2]];
      const Eigen::Vector3d lo = a.cwiseMin(b).cwiseMin(c) / h, hi = a.cwiseMax(b).cwiseMax(c) / h;
      int from[3], to[3];
      for (int axis = 0; axis < 3; ++axis) {
        from[axis] = std::max(0, int(std::ceil(lo[axis] - 1)) - shape.origin[axis]);
        to[axis] = std::min(shape.dims[axis] - 1, int(std::floor(hi[axis] + 1)) - shape.origin[axis]);
      }
      for (int i = from[0]; i <= to[0]; ++i)
        for (int j = from[1]; j <= to[1]; ++j)
          for (int k = from[2]; k <= to[2]; ++k) {
            const Eigen::Vector3d p = shape.world(i, j, k);
            const double d2 = (closest_point_on_triangle(p, a, b, c) - p).squaredNorm();
            if (d2 > h * h) continue;
            const float d = float(std::sqrt(d2));
            uint32_t bits;
            std::memcpy(&bits, &d, sizeof bits);
            const uint64_t key = (uint64_t(bits) << 32) | uint32_t(t);
            std::atomic<uint64_t>& slot = best[shape.index(i, j, k)];
            uint64_t seen = slot.load(std::memory_order_relaxed);
            while (key < seen && !slot.compare_exchange_weak(seen, key, std::memory_order_relaxed)) {
            }
          }
    }
  });
  tbb::parallel_for(tbb::blocked_range<size_t>(0, total, 1 << 16), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t i = r.begin(); i != r.end(); ++i) {
      const uint64_t key = best[i].load(std::memory_order_relaxed);
      if (key == kEmpty) continue;
      const uint32_t bits = uint32_t(key >> 32);
      std::memcpy(&dist[i], &bits, sizeof bits);
      closest[i] = int32_t(uint32_t(key));
    }
  });
}

PseudoNormals::PseudoNormals(const TriMesh& mesh) : vertex_(mesh.vertices.size(), Eigen::Vector3d::Zero()) {
  face_.reserve(mesh.triangles.size());
  edge_.reserve(mesh.triangles.size() * 2);
  for (const auto& f : mesh.triangles) {
    const Eigen::Vector3d* p[3] = {&mesh.vertices[f[0]], &mesh.vertices[f[1]], &mesh.vertices[f[2]]};
    const Eigen::Vector3d area = (*p[1] - *p[0]).cross(*p[2] - *p[0]);
    const Eigen::Vector3d n = area.norm() > 0 ? Eigen::Vector3d(area / area.norm()) : Eigen::Vector3d::Zero();
    face_.push_back(n);
    for (int corner = 0; corner < 3; ++corner) {
      const Eigen::Vector3d u = *p[(corner + 1) % 3] - *p[corner], v = *p[(corner + 2) % 3] - *p[corner];
      const double angle = std::atan2(u.cross(v).norm(), u.dot(v));
      vertex_[size_t(f[corner])] += angle * n;
      // try_emplace with an explicit zero: a default Eigen vector is uninitialised.
      edge_.try_emplace(edge_key(f[corner], f[(corner + 1) % 3]), Eigen::Vector3d::Zero()).first->second += n;
    }
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
    n = edge_.at(edge_key(f[(opposite + 1) % 3], f[(opposite + 2) % 3]));
  } else {
    n = face_[size_t(triangle)];
  }
  const double along = (p - c).dot(n), norms = (p - c).norm() * n.norm();
  if (!(std::abs(along) >= 0.2 * norms) || norms == 0) return 0;
  return along < 0 ? -1 : 1;
}

}  // namespace spx
