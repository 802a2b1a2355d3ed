#pragma once
// A dense block of voxels in OpenVDB's index space: voxel (i,j,k) of the block sits at index
// coordinate origin + (i,j,k), whose center is at world position voxel_size * (origin + (i,j,k)).
// Memory layout is OpenVDB's LayoutZYX (z fastest), so the block can be handed to tools::Dense.
#include <Eigen/Core>
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <new>
#include <vector>

namespace spx {

struct GridShape {
  Eigen::Vector3i origin = Eigen::Vector3i::Zero();
  Eigen::Vector3i dims = Eigen::Vector3i::Zero();
  double voxel_size = 1;

  size_t count() const { return size_t(dims.x()) * size_t(dims.y()) * size_t(dims.z()); }
  size_t index(int i, int j, int k) const { return size_t(k) + size_t(dims.z()) * (size_t(j) + size_t(dims.y()) * size_t(i)); }
  Eigen::Vector3i coords(size_t idx) const {
    if (idx <= UINT32_MAX) {  // 32-bit division where it fits: several times faster, and this sits in hot loops
      const uint32_t n = uint32_t(idx), nz = uint32_t(dims.z()), ny = uint32_t(dims.y());
      const uint32_t line = n / nz;
      return {int(line / ny), int(line % ny), int(n - line * nz)};
    }
    const int k = int(idx % size_t(dims.z()));
    idx /= size_t(dims.z());
    return {int(idx / size_t(dims.y())), int(idx % size_t(dims.y())), k};
  }
  Eigen::Vector3d world(int i, int j, int k) const {
    return voxel_size * Eigen::Vector3d(origin.x() + i, origin.y() + j, origin.z() + k);
  }
  // Calls visit(m) for every face neighbour m of voxel idx (at coords c) inside the block.
  template <class Visit>
  void for_each_face_neighbour(size_t idx, const Eigen::Vector3i& c, Visit&& visit) const {
    const size_t sy = size_t(dims.z()), sx = size_t(dims.y()) * sy;
    if (c.x() > 0) visit(idx - sx);
    if (c.x() + 1 < dims.x()) visit(idx + sx);
    if (c.y() > 0) visit(idx - sy);
    if (c.y() + 1 < dims.y()) visit(idx + sy);
    if (c.z() > 0) visit(idx - 1);
    if (c.z() + 1 < dims.z()) visit(idx + 1);
  }
  Eigen::Vector3d world(size_t idx) const {
    const Eigen::Vector3i c = coords(idx);
    return world(c.x(), c.y(), c.z());
  }
};

// A std::vector whose elements are left uninitialised when it is sized: a grid that a parallel
// loop fills first then has its pages zeroed by the kernel on every core, not on one.
template <class T>
struct UninitializedAllocator : std::allocator<T> {
  template <class U>
  struct rebind {
    using other = UninitializedAllocator<U>;
  };
  UninitializedAllocator() = default;
  template <class U>
  UninitializedAllocator(const UninitializedAllocator<U>&) noexcept {}
  template <class U>
  void construct(U* p) noexcept {
    ::new (static_cast<void*>(p)) U;
  }
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};
template <class T>
using GridVector = std::vector<T, UninitializedAllocator<T>>;

struct DenseField {
  GridShape shape;
  float background = 0;       // value of voxels far outside (positive)
  std::vector<float> values;  // signed distance, negative inside
};

// A lower bound on the depth of c in the field's solid (0 outside its block): distance is
// 1-Lipschitz, so the deepest of the 8 voxels around c less its offset to c.
inline double depth_bound(const DenseField& field, const Eigen::Vector3d& c) {
  const GridShape& g = field.shape;
  const Eigen::Vector3d at = c / g.voxel_size - g.origin.cast<double>();
  const Eigen::Vector3i lo = at.array().floor().cast<int>();
  double best = 0;
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3i v = lo + Eigen::Vector3i(corner & 1, (corner >> 1) & 1, corner >> 2);
    if ((v.array() < 0).any() || (v.array() >= g.dims.array()).any()) continue;
    const double depth = -field.values[g.index(v.x(), v.y(), v.z())];
    best = std::max(best, depth - (g.world(v.x(), v.y(), v.z()) - c).norm());
  }
  return best;
}

}  // namespace spx
