#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>

#include "mesh/winding_number.hpp"
#include "sdf/sdf_work.hpp"
#include "sdf/surface_layer.hpp"

namespace spx::detail {
namespace {

// Marks the voxels the surface layer encloses. A region of non-layer voxels is inside when
// the layer voxels around it are: a surface crossing between face neighbours lies within half
// a voxel of one of them, which is then in the layer. So a flood from every inside layer voxel
// reaches exactly the inside regions, in time proportional to the inside, not to the grid. One
// winding number per region confirms it, so that a wrongly signed layer voxel cannot flood the
// outside. `winding_inside(points)` answers for a batch. The flood fills runs along z (the
// contiguous axis) and seeds the four lines beside each run once per open stretch: memory in
// order, a push per run instead of per voxel.
template <class Winding>
void fill_inside(const GridShape& shape, const std::vector<size_t>& layer_list, Winding&& winding_inside,
                   GridVector<uint8_t>& flags) {
  const size_t nz = size_t(shape.dims.z()), sx = size_t(shape.dims.y()) * nz;
  auto open = [&](size_t idx) { return !(flags[idx] & (kLayer | kSeen)); };
  std::vector<std::pair<size_t, size_t>> runs;  // [first, last] along z, region by region
  std::vector<size_t> region_start, stack;
  std::vector<Eigen::Vector3d> probes;
  for (size_t wall : layer_list) {
    if (!(flags[wall] & kInside)) continue;
    shape.for_each_face_neighbour(wall, shape.coords(wall), [&](size_t start) {
      if (!open(start)) return;
      region_start.push_back(runs.size());
      probes.push_back(shape.world(start));
      stack.assign(1, start);
      while (!stack.empty()) {
        const size_t idx = stack.back();
        stack.pop_back();
        if (!open(idx)) continue;
        const size_t line = idx - idx % nz;
        size_t first = idx, last = idx;
        while (first > line && open(first - 1)) --first;
        while (last + 1 < line + nz && open(last + 1)) ++last;
        for (size_t m = first; m <= last; ++m) flags[m] |= kSeen;
        runs.emplace_back(first, last);
        const Eigen::Vector3i c = shape.coords(first);
        auto seed_beside = [&](size_t from) {  // the voxels beside [first, last] on one line
          bool was_open = false;
          for (size_t m = from; m <= from + (last - first); ++m) {
            const bool is_open = open(m);
            if (is_open && !was_open) stack.push_back(m);
            was_open = is_open;
          }
        };
        if (c.x() > 0) seed_beside(first - sx);
        if (c.x() + 1 < shape.dims.x()) seed_beside(first + sx);
        if (c.y() > 0) seed_beside(first - nz);
        if (c.y() + 1 < shape.dims.y()) seed_beside(first + nz);
      }
    });
  }
  region_start.push_back(runs.size());
  const std::vector<uint8_t> inside = winding_inside(probes);
  for (size_t r = 0; r < probes.size(); ++r)
    if (inside[r])
      for (size_t n = region_start[r]; n < region_start[r + 1]; ++n)
        for (size_t m = runs[n].first; m <= runs[n].second; ++m) flags[m] |= kInside;
}

}  // namespace

// 2a. Sign of a closed, manifold, consistently oriented single surface: the angle-weighted
//     pseudo-normal of each layer voxel's closest feature (Baerentzen & Aanaes 2005), then one
//     generalized winding number per region the layer encloses.
void sign_closed_surface(SdfWork& w) {
  const TriMesh& mesh = w.mesh;
  const GridShape& shape = w.shape;
  SdfStats& stats = w.stats;
  const auto& tri = w.tri;
  auto& flags = w.flags;
  const std::vector<size_t>& layer_list = w.layer_list;
  stats.sign_method = "pseudo-normals in the surface layer, one winding number per enclosed region (closed surface)";
  const PseudoNormals normals(mesh);
  std::vector<uint8_t> tangent(layer_list.size(), 0);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, layer_list.size(), 4096), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t n = r.begin(); n != r.end(); ++n) {
      const size_t idx = layer_list[n];
      const int side = normals.side(mesh, tri[idx], shape.world(idx));
      if (side < 0) flags[idx] |= kInside;
      tangent[n] = side == 0;
    }
  });
  // Winding numbers for a batch of points, in parallel: a handful cost less summed exactly
  // than a tree costs to build.
  auto winding_inside = [&](const std::vector<Eigen::Vector3d>& points) {
    std::vector<uint8_t> in(points.size());
    std::unique_ptr<WindingNumber> tree;
    if (points.size() > 32) tree = std::make_unique<WindingNumber>(mesh);
    tbb::parallel_for(size_t(0), points.size(), [&](size_t n) {
      in[n] = tree ? tree->inside(points[n]) : winding_number_exact(mesh, points[n]) > 0.5;
    });
    stats.winding_evaluations += points.size();
    return in;
  };
  std::vector<Eigen::Vector3d> tangent_points;
  for (size_t n = 0; n < layer_list.size(); ++n)
    if (tangent[n]) tangent_points.push_back(shape.world(layer_list[n]));
  const std::vector<uint8_t> tangent_inside = winding_inside(tangent_points);
  for (size_t n = 0, m = 0; n < layer_list.size(); ++n)
    if (tangent[n]) {
      const size_t idx = layer_list[n];
      set_flag(flags[idx], kInside, tangent_inside[m++]);
    }
  fill_inside(shape, layer_list, winding_inside, flags);
}

// 2b. Anything else (holes, flipped faces, several pieces that may overlap): the winding
//     number at every voxel, or block by block. The winding number is harmonic off the surface:
//     in a block of kSignBlock^3 voxels that no triangle comes within a voxel of (no layer voxel
//     among them or its far corners) and whose 8 corners all lie on one side of 1/2 by more
//     than kSignClear, every voxel is on that side. Other blocks are evaluated voxel by voxel.
//     Exhaustive evaluation (`every_voxel`) is the reference the tests compare against.
constexpr int kSignBlock = 4;
constexpr double kSignClear = 0.2;

void sign_by_winding_numbers(SdfWork& w, bool every_voxel) {
  const TriMesh& mesh = w.mesh;
  const GridShape& shape = w.shape;
  SdfStats& stats = w.stats;
  auto& flags = w.flags;
  stats.sign_method = "winding number at every voxel (not a single closed surface)";
  const WindingNumber wn(mesh);
  // Outside the bounding box |w| <= 1/2 (a plane separates the query from the mesh).
  const Eigen::AlignedBox3d box = mesh.bounds();
  std::atomic<size_t> evaluations{0};
  auto winding = [&](size_t idx) {
    const Eigen::Vector3d p = shape.world(idx);
    if (!box.contains(p)) return 0.0;
    ++evaluations;
    return wn(p);
  };
  auto sign_voxels = [&](const Eigen::Vector3i& lo, const Eigen::Vector3i& hi) {  // inclusive
    size_t local = 0;
    for (int x = lo.x(); x <= hi.x(); ++x)
      for (int y = lo.y(); y <= hi.y(); ++y)
        for (int z = lo.z(); z <= hi.z(); ++z) {
          const size_t idx = shape.index(x, y, z);
          const Eigen::Vector3d p = shape.world(idx);
          if (!box.contains(p)) continue;
          if (wn.inside(p)) flags[idx] |= kInside;
          ++local;
        }
    evaluations += local;
  };
  const Eigen::Vector3i& dims = shape.dims;
  if (every_voxel) {
    tbb::parallel_for(0, dims.x(), [&](int x) { sign_voxels({x, 0, 0}, {x, dims.y() - 1, dims.z() - 1}); });
    stats.winding_evaluations = evaluations;
    return;
  }
  // Corners: the voxels at multiples of kSignBlock (and the last one) along each axis.
  const Eigen::Vector3i corners = (dims.array() - 2) / kSignBlock + 2;
  auto corner_coord = [&](int c, int axis) { return std::min(c * kSignBlock, dims[axis] - 1); };
  std::vector<double> at_corner(size_t(corners.prod()));
  auto corner_index = [&](int i, int j, int k) { return size_t(i) + size_t(corners.x()) * (size_t(j) + size_t(corners.y()) * size_t(k)); };
  tbb::parallel_for(0, corners.z(), [&](int k) {
    for (int j = 0; j < corners.y(); ++j)
      for (int i = 0; i < corners.x(); ++i)
        at_corner[corner_index(i, j, k)] = winding(shape.index(corner_coord(i, 0), corner_coord(j, 1), corner_coord(k, 2)));
  });
  const Eigen::Vector3i blocks = corners.array() - 1;
  tbb::parallel_for(0, blocks.z(), [&](int k) {
    for (int j = 0; j < blocks.y(); ++j)
      for (int i = 0; i < blocks.x(); ++i) {
        const Eigen::Vector3i lo(corner_coord(i, 0), corner_coord(j, 1), corner_coord(k, 2));
        const Eigen::Vector3i far(corner_coord(i + 1, 0), corner_coord(j + 1, 1), corner_coord(k + 1, 2));
        double least = 1e300, most = -1e300;
        for (int c = 0; c < 8; ++c) {
          const double v = at_corner[corner_index(i + (c & 1), j + ((c >> 1) & 1), k + (c >> 2))];
          least = std::min(least, v), most = std::max(most, v);
        }
        bool clear = least > 0.5 + kSignClear || most < 0.5 - kSignClear;
        for (int z = lo.z(); clear && z <= far.z(); ++z)
          for (int y = lo.y(); clear && y <= far.y(); ++y)
            for (int x = lo.x(); clear && x <= far.x(); ++x) clear = !(flags[shape.index(x, y, z)] & kLayer);
        // The block's own voxels stop short of the far corners, which the next block owns
        // (the last block along an axis takes them).
        const Eigen::Vector3i hi(i + 1 == blocks.x() ? far.x() : far.x() - 1, j + 1 == blocks.y() ? far.y() : far.y() - 1,
                                 k + 1 == blocks.z() ? far.z() : far.z() - 1);
        if (!clear) {
          sign_voxels(lo, hi);
        } else if (least > 0.5) {
          for (int x = lo.x(); x <= hi.x(); ++x)
            for (int y = lo.y(); y <= hi.y(); ++y)
              for (int z = lo.z(); z <= hi.z(); ++z) flags[shape.index(x, y, z)] |= kInside;
        }
      }
  });
  stats.winding_evaluations = evaluations;
}

}  // namespace spx::detail
