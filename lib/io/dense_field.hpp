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

namespace detail {
// A grid's block on 2 MiB pages where the system grants them (Linux's transparent huge pages on
// request): a pass over a fresh grid then takes one page fault per 2 MiB, not per 4 KiB, and on
// a virtual machine the faults are much of a memory-bound pass's time. Small blocks: operator new.
void* allocate_grid_block(size_t bytes);
void free_grid_block(void* p, size_t bytes) noexcept;
}  // namespace detail

// A std::vector whose elements are left uninitialised when it is sized: a grid that a parallel
// loop fills first then has its pages zeroed by the kernel on every core, not on one.
template <class T>
struct UninitializedAllocator : std::allocator<T> {
  using value_type = T;
  template <class U>
  struct rebind {
    using other = UninitializedAllocator<U>;
  };
  UninitializedAllocator() = default;
  template <class U>
  UninitializedAllocator(const UninitializedAllocator<U>&) noexcept {}
  T* allocate(size_t n) {
    if (n > SIZE_MAX / sizeof(T)) throw std::bad_array_new_length();
    return static_cast<T*>(detail::allocate_grid_block(n * sizeof(T)));
  }
  void deallocate(T* p, size_t n) noexcept { detail::free_grid_block(p, n * sizeof(T)); }
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
  GridVector<float> values;  // signed distance, negative inside (each stage that makes one writes every voxel)
};

// A lower bound on the depth of c in a grid's solid (0 outside the grid): distance is
// 1-Lipschitz, so the deepest of the 8 voxels around c less its offset to c. `depth(index)`:
// a voxel's depth.
template <class Depth>
double depth_bound_in(const GridShape& g, const Eigen::Vector3d& c, Depth&& depth) {
  const Eigen::Vector3d at = c / g.voxel_size - g.origin.cast<double>();
  const Eigen::Vector3i lo = at.array().floor().cast<int>();
  double best = 0;
  // A voxel no deeper than the best so far cannot beat it, whatever its offset: no square root.
  auto offer = [&](int corner, double d) {
    if (!(d > best)) return;
    const Eigen::Vector3i v = lo + Eigen::Vector3i(corner & 1, (corner >> 1) & 1, corner >> 2);
    best = std::max(best, d - (g.world(v.x(), v.y(), v.z()) - c).norm());
  };
  if ((lo.array() >= 0).all() && (lo.array() + 1 < g.dims.array()).all()) {
    // All 8 inside (the usual case): their depths read first, side by side.
    const size_t sz = 1, sy = size_t(g.dims.z()), sx = sy * size_t(g.dims.y());
    const size_t base = g.index(lo.x(), lo.y(), lo.z());
    const double d[8] = {depth(base), depth(base + sx), depth(base + sy), depth(base + sx + sy),
                         depth(base + sz), depth(base + sx + sz), depth(base + sy + sz), depth(base + sx + sy + sz)};
    for (int corner = 0; corner < 8; ++corner) offer(corner, d[corner]);
    return best;
  }
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3i v = lo + Eigen::Vector3i(corner & 1, (corner >> 1) & 1, corner >> 2);
    if ((v.array() < 0).any() || (v.array() >= g.dims.array()).any()) continue;
    offer(corner, depth(g.index(v.x(), v.y(), v.z())));
  }
  return best;
}

inline double depth_bound(const DenseField& field, const Eigen::Vector3d& c) {
  return depth_bound_in(field.shape, c, [&](size_t i) { return -double(field.values[i]); });
}

// A field's interior depths, all that floors under radii need (depth_bound), in a fraction of
// its memory: cropped to the box of its interior voxels and held in 16 bits of 1/512 voxel,
// rounded down (a floor only gets lower; depths past 128 voxels are held at 128).
struct DepthField {
  GridShape shape;  // the interior's box, in the field's index space
  double unit = 0;  // one step of `depth`
  std::vector<uint16_t> depth;
};

inline DepthField depth_field(const DenseField& field) {
  const GridShape& g = field.shape;
  Eigen::Vector3i lo = g.dims, hi = Eigen::Vector3i::Constant(-1);
  for (size_t idx = 0; idx < g.count(); ++idx)
    if (field.values[idx] < 0) {
      const Eigen::Vector3i c = g.coords(idx);
      lo = lo.cwiseMin(c);
      hi = hi.cwiseMax(c);
    }
  DepthField out;
  out.shape.voxel_size = g.voxel_size;
  out.unit = g.voxel_size / 512;
  if ((hi.array() < lo.array()).any()) return out;  // no interior
  out.shape.origin = g.origin + lo;
  out.shape.dims = hi - lo + Eigen::Vector3i::Ones();
  out.depth.assign(out.shape.count(), 0);
  for (int i = 0; i < out.shape.dims.x(); ++i)
    for (int j = 0; j < out.shape.dims.y(); ++j)
      for (int k = 0; k < out.shape.dims.z(); ++k) {
        const double d = -double(field.values[g.index(lo.x() + i, lo.y() + j, lo.z() + k)]) / out.unit;
        out.depth[out.shape.index(i, j, k)] = uint16_t(std::clamp(std::floor(d), 0.0, 65535.0));
      }
  return out;
}

// depth_bound's floor from the held depths: never above the field's own.
inline double depth_bound(const DepthField& field, const Eigen::Vector3d& c) {
  return depth_bound_in(field.shape, c, [&](size_t i) { return field.unit * field.depth[i]; });
}

}  // namespace spx
