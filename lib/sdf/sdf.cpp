#include "sdf/sdf.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <tbb/parallel_sort.h>

#include "core/error.hpp"
#include "core/format.hpp"
#include "mesh/mesh_query.hpp"
#include "mesh/solid_boundary.hpp"
#include "sdf/edt.hpp"
#include "sdf/sdf_work.hpp"
#include "sdf/surface_layer.hpp"

namespace spx {
using namespace detail;
namespace {

// Working set per voxel: distance, triangle, flags, the feature transform's seed and squared
// distance, the layer index (touched at surface voxels only).
constexpr double kBytesPerVoxel = 4 + 4 + 1 + 4 + 4 + 4;

std::string gib(double v) {
  char text[64];
  std::snprintf(text, sizeof text, "%.1f GiB", v);
  return text;
}

// The triangles laid out for the distance loops: corners side by side (two cache lines per
// triangle instead of an index and three scattered vertices), with the triangle's plane: a
// candidate whose plane is farther than the best distance so far cannot win, and is skipped
// without the exact test.
struct TriangleTable {
  struct Entry {
    Eigen::Vector3d a, b, c, normal;  // unit normal (zero for a degenerate triangle)
    double offset;                    // normal . a
  };
  std::vector<Entry> entries;
  explicit TriangleTable(const TriMesh& mesh) {
    entries.reserve(mesh.triangles.size());
    for (const auto& f : mesh.triangles) {
      Entry e{mesh.vertices[f[0]], mesh.vertices[f[1]], mesh.vertices[f[2]], Eigen::Vector3d::Zero(), 0};
      const Eigen::Vector3d n = (e.b - e.a).cross(e.c - e.a);
      if (n.norm() > 0) e.normal = n / n.norm();
      e.offset = e.normal.dot(e.a);
      entries.push_back(e);
    }
  }
  // Squared distance from p to triangle t, or +inf when it certainly exceeds `best`.
  double distance2(int32_t t, const Eigen::Vector3d& p, double best) const {
    const Entry& e = entries[size_t(t)];
    const double plane = e.normal.dot(p) - e.offset;
    if (plane * plane > best * (1 + 1e-9)) return std::numeric_limits<double>::infinity();
    return (closest_point_on_triangle(p, e.a, e.b, e.c) - p).squaredNorm();
  }
};

// The candidate triangles of the voxels whose nearest surface voxel is `seed`: the closest
// triangles of the seed and its 18 face and edge neighbours (not the corners: the refine
// sweeps do the rest), each once, the seed's own first so that the bound prunes early.
struct Candidates {
  int32_t tri[19];
  int count = 0;
  Candidates(const GridShape& shape, const GridVector<int32_t>& tri_of, const GridVector<uint8_t>& flags, size_t seed) {
    const Eigen::Vector3i c = shape.coords(seed);
    tri[count++] = tri_of[seed];
    for (int di = -1; di <= 1; ++di)
      for (int dj = -1; dj <= 1; ++dj)
        for (int dk = -1; dk <= 1; ++dk) {
          if (std::abs(di) + std::abs(dj) + std::abs(dk) > 2) continue;
          const int i = c.x() + di, j = c.y() + dj, k = c.z() + dk;
          if (i < 0 || j < 0 || k < 0 || i >= shape.dims.x() || j >= shape.dims.y() || k >= shape.dims.z()) continue;
          const size_t m = shape.index(i, j, k);
          if (!(flags[m] & kLayer)) continue;  // only the rasterizer's triangles, never another voxel's result
          if (std::find(tri, tri + count, tri_of[m]) == tri + count) tri[count++] = tri_of[m];
        }
  }
  // The exact closest of them to p (the lowest index on ties); `distance` receives the distance.
  int32_t closest_to(const TriangleTable& triangles, const Eigen::Vector3d& p, double* distance) const {
    int32_t best_tri = tri[0];
    double best = triangles.distance2(best_tri, p, std::numeric_limits<double>::infinity());
    for (int n = 1; n < count; ++n) {
      const double e = triangles.distance2(tri[n], p, best);
      if (e < best || (e == best && tri[n] < best_tri)) {
        best = e;
        best_tri = tri[n];
      }
    }
    *distance = std::sqrt(best);
    return best_tri;
  }
};

// The mesh with its triangles in Morton order of their centroids' voxels: the distance loops
// then find the triangles of one neighbourhood side by side in memory (in cache) instead of
// scattered over the whole list. Triangle indices below are in this order.
TriMesh in_spatial_order(const TriMesh& mesh, const GridShape& shape) {
  auto spread = [](uint64_t v) {  // 21 bits -> every third bit of 63
    v &= 0x1fffff;
    v = (v | v << 32) & 0x1f00000000ffffull;
    v = (v | v << 16) & 0x1f0000ff0000ffull;
    v = (v | v << 8) & 0x100f00f00f00f00full;
    v = (v | v << 4) & 0x10c30c30c30c30c3ull;
    v = (v | v << 2) & 0x1249249249249249ull;
    return v;
  };
  std::vector<std::pair<uint64_t, int32_t>> order(mesh.triangles.size());
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& f = mesh.triangles[t];
    const Eigen::Vector3d c = (mesh.vertices[f[0]] + mesh.vertices[f[1]] + mesh.vertices[f[2]]) / (3 * shape.voxel_size);
    uint64_t key = 0;
    for (int axis = 0; axis < 3; ++axis)
      key |= spread(uint64_t(std::clamp(int64_t(std::floor(c[axis])) - shape.origin[axis], int64_t(0), int64_t(0x1fffff)))) << axis;
    order[t] = {key, int32_t(t)};
  }
  tbb::parallel_sort(order.begin(), order.end());  // keys unique: (code, triangle)
  TriMesh sorted;
  sorted.vertices = mesh.vertices;
  sorted.triangles.reserve(order.size());
  for (const auto& [key, t] : order) sorted.triangles.push_back(mesh.triangles[size_t(t)]);
  return sorted;
}

// Grid placement for a mesh: voxel size and padded extent. Throws Error(usage) on bad options
// and GridTooLarge when the grid would not fit in memory.
GridShape plan_grid(const TriMesh& mesh, const SdfOptions& opt, double* estimated_gib) {
  if (opt.voxel_size < 0 || !std::isfinite(opt.voxel_size))
    fail_option("voxel_size", "must be a positive number");
  if (opt.voxel_size == 0 && opt.resolution < 1) fail_option("resolution", "must be at least 1");
  if (opt.band < 1 || opt.band > 64) fail_option("band", "must be between 1 and 64 voxels");
  const Eigen::AlignedBox3d box = mesh.bounds();
  const double longest = box.sizes().maxCoeff();
  if (!(longest > 0) || !std::isfinite(longest)) {
    const double magnitude = box.isEmpty() ? 0.0 : box.min().cwiseAbs().maxCoeff();
    fail_input("", magnitude > 1e6 ? "all vertices coincide: mesh readers use single precision, which cannot separate "
                                     "them at coordinates near " + num(magnitude) +
                                     "; move the mesh near the origin"
                                   : std::string("mesh has zero extent (all vertices coincide)"));
  }

  GridShape shape;
  shape.voxel_size = voxel_size_for(mesh, opt);
  const int pad = opt.band + 1;
  Eigen::Vector3d lo = (box.min() / shape.voxel_size).array().floor() - pad;
  Eigen::Vector3d hi = (box.max() / shape.voxel_size).array().ceil() + pad;
  const Eigen::Vector3d dims = hi - lo + Eigen::Vector3d::Ones();
  const double voxels = dims.prod();
  const double need = voxels * kBytesPerVoxel / double(1ull << 30);
  if (estimated_gib) *estimated_gib = need;
  const double index_limit = 2.0e9;
  if (!(lo.cwiseAbs().maxCoeff() < index_limit && hi.cwiseAbs().maxCoeff() < index_limit))
    fail_option("voxel_size", "is too small for the mesh's coordinates (index space overflows)");
  if (need > opt.memory_limit_gib || voxels >= 2.0e9) {
    char grid[200];
    std::snprintf(grid, sizeof grid, "a %.0f x %.0f x %.0f grid needs about %s of memory, over the %.0f GiB limit",
                  dims.x(), dims.y(), dims.z(), gib(need).c_str(), opt.memory_limit_gib);
    throw GridTooLarge(grid, "use a coarser resolution (or a higher memory limit on a larger machine)");
  }
  // OpenVDB's transforms need voxel_size^3 >= 3e-15 (math::Tolerance<double> in ScaleMap).
  constexpr double kSmallestVoxel = 1.5e-5;
  if (shape.voxel_size < kSmallestVoxel)
    fail_unsupported("", "voxel size " + num(shape.voxel_size) + " is below OpenVDB's smallest (" +
                             num(kSmallestVoxel) + " in file units); scale the mesh up (e.g. to millimetres)");
  shape.origin = lo.cast<int>();
  shape.dims = dims.cast<int>();
  return shape;
}

// 1. The surface layer: every voxel within one voxel of the surface, with its exact distance
//    and closest triangle (each triangle visits the voxels of its box grown by a voxel). Any
//    surface crossing between two face-adjacent voxel centres lies within half a voxel of one
//    of them, so the layer separates inside from outside.
void rasterize_layer(SdfWork& w) {
  const TriMesh& mesh = w.mesh;
  const GridShape& shape = w.shape;
  const size_t total = shape.count();
  DenseField& field = w.field;
  auto& tri = w.tri;
  auto& flags = w.flags;
  field.values.resize(total);  // uninitialized: filled here side by side, pages touched by both cores
  tbb::parallel_for(tbb::blocked_range<size_t>(0, total, 1 << 16), [&](const tbb::blocked_range<size_t>& r) {
    std::fill(field.values.begin() + ptrdiff_t(r.begin()), field.values.begin() + ptrdiff_t(r.end()), field.background);
    std::fill(tri.begin() + ptrdiff_t(r.begin()), tri.begin() + ptrdiff_t(r.end()), -1);
    std::fill(flags.begin() + ptrdiff_t(r.begin()), flags.begin() + ptrdiff_t(r.end()), 0);
  });
  rasterize_surface_layer(mesh, shape, field.values, tri);
  w.layer_list = indices_where(total, [&](size_t idx) { return tri[idx] >= 0; });
  tbb::parallel_for(tbb::blocked_range<size_t>(0, w.layer_list.size(), 4096), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t n = r.begin(); n != r.end(); ++n) flags[w.layer_list[n]] = kLayer;
  });
  w.stats.surface_voxels = w.layer_list.size();
}

// 3a. The voxels that get an interior distance: every inside voxel off the layer, and outside
//     the band of `band` voxels unless `inside_only` (the rest stays background).
std::vector<size_t> mark_wanted(SdfWork& w, const GridVector<int32_t>& nearest, int band, bool inside_only) {
  const GridShape& shape = w.shape;
  const size_t total = shape.count();
  const double h = shape.voxel_size;
  auto& flags = w.flags;
  const double band_reach = (band + 1) * h;
  const int nx = shape.dims.x(), ny = shape.dims.y(), nz = shape.dims.z();
  const size_t sy = size_t(nz);
  tbb::parallel_for(tbb::blocked_range<int>(0, nx * ny, 16), [&](const tbb::blocked_range<int>& r) {
    for (int l = r.begin(); l != r.end(); ++l) {
      const int i = l / ny, j = l % ny;
      const size_t base = size_t(l) * sy;
      for (int k = 0; k < nz; ++k) {
        const size_t idx = base + size_t(k);
        const int32_t seed = nearest[idx];
        if ((flags[idx] & kLayer) || seed < 0) continue;
        if (!(flags[idx] & kInside)) {
          if (inside_only) continue;
          // Outside: only the band is stored. The seed's k is cheap to get; most far voxels fail
          // on it before the full test.
          const int seed_k = int(uint32_t(seed) % uint32_t(sy));  // indices fit 32 bits (plan_grid)
          if (std::abs(seed_k - k) * h > band_reach) continue;
          if ((shape.world(i, j, k) - shape.world(size_t(seed))).squaredNorm() > band_reach * band_reach) continue;
        }
        flags[idx] |= kWanted;
      }
    }
  });
  return indices_where(total, [&](size_t idx) { return flags[idx] & kWanted; });
}

// 3b. Each wanted voxel's triangle: the best candidate around its nearest surface voxel
//     (`nearest` is used up: its layer voxels' slots are overwritten).
void closest_triangles(SdfWork& w, const TriangleTable& triangles, GridVector<int32_t>& nearest,
                       const std::vector<size_t>& wanted_list) {
  const GridShape& shape = w.shape;
  const std::vector<size_t>& layer_list = w.layer_list;
  DenseField& field = w.field;
  auto& tri = w.tri;
  const auto& flags = w.flags;
  // Grouped by nearest surface voxel: the voxels of a group share its candidate triangles,
  // which then stay in cache while each voxel picks its closest (a counting sort).
  std::vector<size_t> group_start(layer_list.size() + 1, 0);
  GridVector<size_t> by_seed(wanted_list.size());  // every element written by the counting sort
  {
    // A layer voxel's nearest seed is itself: its slot is free to hold its place in the layer
    // list (no grid of its own for that: a fresh grid's pages cost more than the pass).
    tbb::parallel_for(tbb::blocked_range<size_t>(0, layer_list.size(), 4096), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t n = r.begin(); n != r.end(); ++n) nearest[layer_list[n]] = int32_t(n);
    });
    GridVector<int32_t> group(wanted_list.size());
    tbb::parallel_for(tbb::blocked_range<size_t>(0, wanted_list.size(), 4096), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t n = r.begin(); n != r.end(); ++n) group[n] = nearest[size_t(nearest[wanted_list[n]])];
    });
    for (int32_t g : group) ++group_start[size_t(g) + 1];
    for (size_t g = 0; g < layer_list.size(); ++g) group_start[g + 1] += group_start[g];
    std::vector<size_t> fill(group_start.begin(), group_start.end() - 1);
    for (size_t n = 0; n < wanted_list.size(); ++n) by_seed[fill[size_t(group[n])]++] = wanted_list[n];
  }
  tbb::parallel_for(tbb::blocked_range<size_t>(0, layer_list.size(), 256), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t g = r.begin(); g != r.end(); ++g) {
      if (group_start[g] == group_start[g + 1]) continue;
      const Candidates candidates(shape, tri, flags, layer_list[g]);
      for (size_t n = group_start[g]; n != group_start[g + 1]; ++n) {
        const size_t idx = by_seed[n];
        double e;
        tri[idx] = candidates.closest_to(triangles, shape.world(idx), &e);
        field.values[idx] = float(e);
      }
    }
  });
}

// 3c. Two sweeps in which each voxel also tries its six neighbours' triangles (vector
//     propagation): fixes voxels whose nearest surface voxel slid along the surface away from
//     the foot point.
void refine_by_neighbours(SdfWork& w, const TriangleTable& triangles, const std::vector<size_t>& wanted_list) {
  const GridShape& shape = w.shape;
  DenseField& field = w.field;
  auto& tri = w.tri;
  auto& flags = w.flags;
  // After the first sweep, to a voxel that kept its triangle only a neighbour whose triangle
  // changed offers anything new: the others were tested in the last sweep against the same
  // distance. (One that changed tests them all again: its stored distance is rounded to float,
  // so the last sweep may have taken a triangle a rounding farther than one it held.)
  GridVector<int32_t> next_tri(wanted_list.size());
  for (int sweep = 0; sweep < 2; ++sweep) {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, wanted_list.size(), 1024), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t n = r.begin(); n != r.end(); ++n) {
        const size_t idx = wanted_list[n];
        const Eigen::Vector3i c = shape.coords(idx);
        int32_t own = tri[idx];
        next_tri[n] = own;
        int32_t seen[6];
        int count = 0;
        const bool every = sweep == 0 || (flags[idx] & kChanged);
        shape.for_each_face_neighbour(idx, c, [&](size_t m) {
          if (!every && !(flags[m] & kChanged)) return;
          if (tri[m] >= 0 && tri[m] != own && std::find(seen, seen + count, tri[m]) == seen + count) seen[count++] = tri[m];
        });
        if (count == 0) continue;
        const Eigen::Vector3d p = shape.world(c.x(), c.y(), c.z());
        float& value = field.values[idx];  // this voxel's own slot only
        double best = double(value) * double(value);
        for (int q = 0; q < count; ++q) {
          const double e = triangles.distance2(seen[q], p, best);
          if (e < best) {
            best = e;
            own = seen[q];
          }
        }
        next_tri[n] = own;
        if (own != tri[idx]) value = float(std::sqrt(best));
      }
    });
    tbb::parallel_for(tbb::blocked_range<size_t>(0, wanted_list.size(), 4096), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t n = r.begin(); n != r.end(); ++n) {
        const size_t idx = wanted_list[n];
        set_flag(flags[idx], kChanged, next_tri[n] != tri[idx]);
        tri[idx] = next_tri[n];
      }
    });
  }
}

// 4. An open mesh's solid is also bounded across its holes, where there are no triangles:
//    there, bound interior distances by the distance to the solid's outside (every point of
//    the solid's boundary lies within half a voxel diagonal of an outside voxel center).
void bound_across_holes(SdfWork& w) {
  const GridShape& shape = w.shape;
  const size_t total = shape.count();
  const double h = shape.voxel_size;
  DenseField& field = w.field;
  auto& tri = w.tri;
  const auto& flags = w.flags;
  std::vector<uint8_t> outside(total);
  for (size_t idx = 0; idx < total; ++idx) outside[idx] = !(flags[idx] & kInside);
  const GridVector<int32_t> out_nearest = nearest_seed_transform(shape, outside);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, total, 4096), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t idx = r.begin(); idx != r.end(); ++idx) {
      if (!(flags[idx] & kInside) || out_nearest[idx] < 0) continue;
      const double hole = (shape.world(idx) - shape.world(size_t(out_nearest[idx]))).norm() - 0.5 * std::sqrt(3.0) * h;
      // An inside voxel far from any triangle still gets a value.
      if (tri[idx] < 0 || hole < field.values[idx]) field.values[idx] = float(std::max(hole, 0.0));
      if (tri[idx] < 0) tri[idx] = 0;
    }
  });
  w.stats.bounded_by_holes = true;
}

// 5. Distances become signed (negative inside); outside voxels past the band get the background.
void apply_sign(SdfWork& w) {
  const size_t total = w.shape.count();
  DenseField& field = w.field;
  const auto& tri = w.tri;
  const auto& flags = w.flags;
  std::atomic<size_t> interior{0};
  tbb::parallel_for(tbb::blocked_range<size_t>(0, total, 4096), [&](const tbb::blocked_range<size_t>& r) {
    size_t local = 0;
    for (size_t idx = r.begin(); idx != r.end(); ++idx) {
      if (tri[idx] < 0) continue;  // far outside: background
      if (flags[idx] & kInside) {
        field.values[idx] = -field.values[idx];
        ++local;
      } else {
        field.values[idx] = std::min(field.values[idx], field.background);
      }
    }
    interior += local;
  });
  w.stats.interior_voxels = interior;
}

}  // namespace

double voxel_size_for(const TriMesh& mesh, const SdfOptions& opt) {
  const double longest = mesh.vertices.empty() ? 0 : mesh.bounds().sizes().maxCoeff();
  return opt.voxel_size > 0 ? opt.voxel_size : longest > 0 ? longest / opt.resolution : 0;
}

SdfResult build_sdf(const TriMesh& input, const SdfOptions& opt, Log& log, const SolidBoundary* found) {
  SdfResult result;
  SdfStats& stats = result.stats;
  StageTimer prepare(log, "defects-and-order");
  const GridShape shape = plan_grid(input, opt, &stats.estimated_memory_gib);
  TriMesh mesh;  // the two are independent: side by side
  tbb::parallel_invoke([&] { stats.defects = find_defects(input); }, [&] { mesh = in_spatial_order(input, shape); });
  prepare.stop();
  log.detail("grid " + std::to_string(shape.dims.x()) + "x" + std::to_string(shape.dims.y()) + "x" +
             std::to_string(shape.dims.z()) + ", voxel size " + num(shape.voxel_size));
  result.field.shape = shape;
  result.field.background = float(opt.band * shape.voxel_size);
  SdfWork work(mesh, shape, result.field, stats);
  {
    StageTimer t(log, "surface-layer");
    rasterize_layer(work);
  }
  // Its pseudo-normals tell inside from outside as the winding number does only when it faces
  // outward: one that faces inward (w = -1 within) is signed by winding numbers, as any other.
  const bool single_closed =
      stats.defects.watertight() && stats.defects.components == 1 && stats.defects.signed_volume > 0;
  {
    StageTimer t(log, "sign");
    if (single_closed) sign_closed_surface(work);
    else sign_by_winding_numbers(work, opt.sign_every_voxel);
  }
  // Distances are to the solid's boundary: walls inside it (overlapping parts) leave the layer,
  // which is laid again from the boundary alone (mesh/solid_boundary.hpp); the sign stays the
  // whole mesh's. A single closed surface is its own boundary.
  TriMesh bounding;
  std::unique_ptr<SdfWork> outer;
  if (!single_closed) {
    StageTimer t(log, "internal-walls");
    const SolidBoundary boundary = found ? SolidBoundary() : solid_boundary(mesh, WindingNumber(mesh));
    const SolidBoundary& b = found ? *found : boundary;
    stats.internal_walls = b.internal;
    stats.split_triangles = b.split;
    if (!b.whole() && !b.mesh.triangles.empty()) {
      bounding = in_spatial_order(b.mesh, shape);
      outer = std::make_unique<SdfWork>(bounding, shape, result.field, stats);
      rasterize_layer(*outer);
      for (size_t idx = 0; idx < shape.count(); ++idx) outer->flags[idx] |= work.flags[idx] & kInside;
    }
  }
  SdfWork& w = outer ? *outer : work;
  // Interior distances: nearest surface voxel by an exact feature transform, then the exact
  // distance to the closest of the triangles around it.
  const TriangleTable triangles(w.mesh);
  StageTimer edt(log, "feature-transform");
  GridVector<int32_t> nearest = nearest_seed_transform(shape, w.flags.data(), kLayer);
  edt.stop();
  {
    StageTimer t(log, "closest-triangles");
    const std::vector<size_t> wanted = mark_wanted(w, nearest, opt.band, opt.inside_only);
    closest_triangles(w, triangles, nearest, wanted);
    t.stop();
    StageTimer r(log, "refine");
    refine_by_neighbours(w, triangles, wanted);
  }
  {
    StageTimer t(log, "values");
    if (!stats.defects.watertight()) bound_across_holes(w);
    apply_sign(w);
  }
  if (stats.interior_voxels == 0 && stats.defects.encloses) {
    const double volume = stats.defects.signed_volume;
    if (negligible_volume(volume, input.bounds().sizes().maxCoeff()))
      fail_input("", "encloses no volume: each of its edges is run as often one way as the other and its signed "
                     "volume is 0 (" + num(volume) + "): its faces given both ways (a double-sided export), or flat, "
                     "so the winding number is nowhere above 1/2; keep one side");
    if (volume < 0)
      fail_input("", "encloses no volume: its triangles face inward (signed volume " + num(volume) +
                         "), so the winding number is -1 within it, and inside is where it exceeds 1/2; flip its faces");
  }
  if (stats.interior_voxels == 0)
    fail_input("", "encloses no volume at this resolution (flat, open with no inside, or thinner than a voxel of " +
                       num(shape.voxel_size) + "); try a finer resolution");
  return result;
}

nlohmann::json SdfStats::to_json() const {
  return {{"defects", defects.to_json()},
          {"sign_method", sign_method},
          {"surface_voxels", surface_voxels},
          {"interior_voxels", interior_voxels},
          {"winding_evaluations", winding_evaluations},
          {"internal_walls", internal_walls},
          {"split_triangles", split_triangles},
          {"bounded_by_holes", bounded_by_holes},
          {"estimated_memory_gib", estimated_memory_gib}};
}

}  // namespace spx
