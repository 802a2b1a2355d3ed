#include "sdf/sdf.hpp"

#include <openvdb/openvdb.h>
#include <openvdb/tools/MeshToVolume.h>

#include <cmath>
#include <deque>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/error.hpp"
#include "core/format.hpp"
#include "mesh/mesh_query.hpp"
#include "mesh/winding_number.hpp"
#include "sdf/edt.hpp"

namespace spx {
namespace {

// Working set per voxel: distances, closest triangle, flags, seed index, EDT distances, labels.
constexpr double kBytesPerVoxel = 4 + 4 + 1 + 4 + 8 + 4 + 4;

char fmt_buf[64];
const char* gib(double v) {
  std::snprintf(fmt_buf, sizeof fmt_buf, "%.1f GiB", v);
  return fmt_buf;
}

// The exact closest of the candidate triangles of voxel `seed` and its 26 neighbours, seen
// from point p. Returns the triangle; `distance` receives the exact distance.
int32_t best_candidate(const TriMesh& mesh, const GridShape& shape, const std::vector<int32_t>& closest, size_t seed,
                       const Eigen::Vector3d& p, double* distance) {
  const Eigen::Vector3i c = shape.coords(seed);
  double best = std::numeric_limits<double>::infinity();
  int32_t best_tri = -1;
  for (int di = -1; di <= 1; ++di)
    for (int dj = -1; dj <= 1; ++dj)
      for (int dk = -1; dk <= 1; ++dk) {
        const int i = c.x() + di, j = c.y() + dj, k = c.z() + dk;
        if (i < 0 || j < 0 || k < 0 || i >= shape.dims.x() || j >= shape.dims.y() || k >= shape.dims.z()) continue;
        const int32_t tri = closest[shape.index(i, j, k)];
        if (tri < 0 || tri == best_tri) continue;
        const auto& f = mesh.triangles[size_t(tri)];
        const double d =
            (closest_point_on_triangle(p, mesh.vertices[f[0]], mesh.vertices[f[1]], mesh.vertices[f[2]]) - p).squaredNorm();
        if (d < best || (d == best && tri < best_tri)) {
          best = d;
          best_tri = tri;
        }
      }
  *distance = std::sqrt(best);
  return best_tri;
}

}  // namespace

GridShape plan_grid(const TriMesh& mesh, const SdfOptions& opt, double* estimated_gib) {
  if (opt.voxel_size < 0 || !std::isfinite(opt.voxel_size))
    fail_usage("--voxel-size", "must be a positive number");
  if (opt.voxel_size == 0 && opt.resolution < 1) fail_usage("--resolution", "must be at least 1");
  if (opt.band < 1 || opt.band > 64) fail_usage("--band", "must be between 1 and 64 voxels");
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
  shape.voxel_size = opt.voxel_size > 0 ? opt.voxel_size : longest / opt.resolution;
  const int pad = opt.band + 1;
  Eigen::Vector3d lo = (box.min() / shape.voxel_size).array().floor() - pad;
  Eigen::Vector3d hi = (box.max() / shape.voxel_size).array().ceil() + pad;
  const Eigen::Vector3d dims = hi - lo + Eigen::Vector3d::Ones();
  const double voxels = dims.prod();
  const double need = voxels * kBytesPerVoxel / double(1ull << 30);
  if (estimated_gib) *estimated_gib = need;
  const double index_limit = 2.0e9;
  if (!(lo.cwiseAbs().maxCoeff() < index_limit && hi.cwiseAbs().maxCoeff() < index_limit))
    fail_usage("--voxel-size", "is too small for the mesh's coordinates (index space overflows)");
  if (need > opt.memory_limit_gib || voxels >= 2.0e9) {
    char msg[400];
    std::snprintf(msg, sizeof msg,
                  "a %.0f x %.0f x %.0f grid needs about %s of memory, over the %.0f GiB limit; use a coarser "
                  "--resolution (or raise --memory-limit on a larger machine)",
                  dims.x(), dims.y(), dims.z(), gib(need), opt.memory_limit_gib);
    fail_unsupported("", msg);
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

SdfResult build_sdf(const TriMesh& mesh, const SdfOptions& opt, Log& log) {
  SdfResult result;
  SdfStats& stats = result.stats;
  stats.defects = find_defects(mesh);
  const GridShape shape = plan_grid(mesh, opt, &stats.estimated_memory_gib);
  const double h = shape.voxel_size;
  const size_t total = shape.count();
  log.detail("grid " + std::to_string(shape.dims.x()) + "x" + std::to_string(shape.dims.y()) + "x" +
             std::to_string(shape.dims.z()) + ", voxel size " + num(h));

  // 1. Unsigned narrow band with the closest triangle per voxel, from OpenVDB.
  std::vector<float> dist(total, std::numeric_limits<float>::infinity());
  std::vector<int32_t> closest(total, -1);
  {
    StageTimer t(log, "band");
    openvdb::initialize();
    std::vector<openvdb::Vec3s> points;
    points.reserve(mesh.vertices.size());
    for (const auto& v : mesh.vertices)
      points.emplace_back(float(v.x() / h), float(v.y() / h), float(v.z() / h));
    std::vector<openvdb::Vec3I> tris;
    tris.reserve(mesh.triangles.size());
    for (const auto& f : mesh.triangles) tris.emplace_back(f[0], f[1], f[2]);
    openvdb::tools::QuadAndTriangleDataAdapter<openvdb::Vec3s, openvdb::Vec3I> adapter(points, tris);
    auto xform = openvdb::math::Transform::createLinearTransform(h);
    openvdb::Int32Grid index_grid(-1);
    auto band = openvdb::tools::meshToVolume<openvdb::FloatGrid>(
        adapter, *xform, float(opt.band), float(opt.band), openvdb::tools::UNSIGNED_DISTANCE_FIELD, &index_grid);
    auto index_acc = index_grid.getConstAccessor();
    for (auto it = band->cbeginValueOn(); it; ++it) {
      const openvdb::Coord c = it.getCoord();
      const Eigen::Vector3i local = Eigen::Vector3i(c.x(), c.y(), c.z()) - shape.origin;
      if ((local.array() < 0).any() || (local.array() >= shape.dims.array()).any()) continue;
      const int32_t tri = index_acc.getValue(c);
      if (tri < 0) continue;
      const size_t idx = shape.index(local.x(), local.y(), local.z());
      dist[idx] = *it;
      closest[idx] = tri;
    }
  }

  // OpenVDB's values deeper in the band are propagated, not exact. Keep its closest triangles
  // only in the surface layer (within a voxel of the surface, where they come from direct
  // voxelisation), refined against the neighbours' candidates; every other voxel gets its
  // distance from the surface layer through the feature transform below.
  std::vector<uint8_t> surface_layer(total, 0);
  {
    StageTimer t(log, "surface-layer");
    std::vector<size_t> band;
    for (size_t i = 0; i < total; ++i)
      if (closest[i] >= 0) band.push_back(i);
    std::vector<int32_t> refined(closest);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, band.size(), 512), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t n = r.begin(); n != r.end(); ++n) {
        const size_t idx = band[n];
        if (dist[idx] > 1.5 * h) continue;
        double best;
        refined[idx] = best_candidate(mesh, shape, closest, idx, shape.world(idx), &best);
        dist[idx] = float(best);
      }
    });
    closest.swap(refined);
    for (size_t idx : band)
      if (dist[idx] <= h) surface_layer[idx] = 1;
  }

  // 2. Sign: generalized winding number at band voxels; elsewhere per connected region
  //    when the mesh is watertight (w is then constant off the surface), else per voxel.
  const WindingNumber wn(mesh);
  std::vector<uint8_t> inside(total, 0), in_band(total, 0);
  std::vector<size_t> band_list;
  for (size_t i = 0; i < total; ++i)
    if (closest[i] >= 0) {
      in_band[i] = 1;
      band_list.push_back(i);
    }
  stats.band_voxels = band_list.size();
  {
    StageTimer t(log, "sign");
    tbb::parallel_for(tbb::blocked_range<size_t>(0, band_list.size(), 1024), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t n = r.begin(); n != r.end(); ++n) inside[band_list[n]] = wn.inside(shape.world(band_list[n]));
    });
    stats.winding_evaluations = band_list.size();
    const int nx = shape.dims.x(), ny = shape.dims.y(), nz = shape.dims.z();
    if (stats.defects.watertight()) {
      stats.sign_method = "winding number at band voxels, one per region elsewhere (watertight mesh)";
      std::vector<uint8_t> seen(in_band);
      std::vector<size_t> queue;
      for (size_t start = 0; start < total; ++start) {
        if (seen[start]) continue;
        const uint8_t sign = wn.inside(shape.world(start));
        ++stats.winding_evaluations;
        queue.assign(1, start);
        seen[start] = 1;
        while (!queue.empty()) {
          const size_t idx = queue.back();
          queue.pop_back();
          inside[idx] = sign;
          const Eigen::Vector3i c = shape.coords(idx);
          const int n[6][3] = {{-1, 0, 0}, {1, 0, 0}, {0, -1, 0}, {0, 1, 0}, {0, 0, -1}, {0, 0, 1}};
          for (const auto& d : n) {
            const int i = c.x() + d[0], j = c.y() + d[1], k = c.z() + d[2];
            if (i < 0 || j < 0 || k < 0 || i >= nx || j >= ny || k >= nz) continue;
            const size_t m = shape.index(i, j, k);
            if (!seen[m]) {
              seen[m] = 1;
              queue.push_back(m);
            }
          }
        }
      }
    } else {
      stats.sign_method = "winding number at every voxel (mesh is not watertight)";
      // Outside the bounding box |w| <= 1/2 (a plane separates the query from the mesh).
      const Eigen::AlignedBox3d box = mesh.bounds();
      std::atomic<size_t> evaluations{0};
      tbb::parallel_for(tbb::blocked_range<size_t>(0, total, 4096), [&](const tbb::blocked_range<size_t>& r) {
        size_t local = 0;
        for (size_t idx = r.begin(); idx != r.end(); ++idx) {
          if (in_band[idx]) continue;
          const Eigen::Vector3d p = shape.world(idx);
          if (!box.contains(p)) continue;
          inside[idx] = wn.inside(p);
          ++local;
        }
        evaluations += local;
      });
      stats.winding_evaluations += evaluations;
    }
  }

  // 3. Interior distances: nearest band voxel by an exact feature transform, then the exact
  //    distance to that voxel's closest triangle.
  DenseField& field = result.field;
  field.shape = shape;
  field.background = float(opt.band * h);
  field.values.assign(total, field.background);
  {
    StageTimer t(log, "interior");
    const std::vector<int32_t> nearest = nearest_seed_transform(shape, surface_layer);
    // Each voxel's triangle: the best candidate around its nearest surface voxel, then two
    // sweeps in which it also tries its six neighbours' triangles (vector propagation), which
    // fixes voxels whose nearest surface voxel slid along the surface away from the foot point.
    std::vector<int32_t> tri(total, -1);
    std::vector<float> d(total, std::numeric_limits<float>::infinity());
    auto wanted = [&](size_t idx) { return !surface_layer[idx] && (inside[idx] || in_band[idx]) && nearest[idx] >= 0; };
    tbb::parallel_for(tbb::blocked_range<size_t>(0, total, 4096), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t idx = r.begin(); idx != r.end(); ++idx) {
        if (surface_layer[idx]) {
          tri[idx] = closest[idx];
          d[idx] = dist[idx];
        } else if (wanted(idx)) {
          double e;
          tri[idx] = best_candidate(mesh, shape, closest, size_t(nearest[idx]), shape.world(idx), &e);
          d[idx] = float(e);
        }
      }
    });
    const int nx = shape.dims.x(), ny = shape.dims.y(), nz = shape.dims.z();
    for (int sweep = 0; sweep < 2; ++sweep) {
      std::vector<int32_t> next(tri);
      tbb::parallel_for(tbb::blocked_range<size_t>(0, total, 4096), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t idx = r.begin(); idx != r.end(); ++idx) {
          if (!wanted(idx)) continue;
          const Eigen::Vector3i c = shape.coords(idx);
          const Eigen::Vector3d p = shape.world(idx);
          const int off[6][3] = {{-1, 0, 0}, {1, 0, 0}, {0, -1, 0}, {0, 1, 0}, {0, 0, -1}, {0, 0, 1}};
          for (const auto& o : off) {
            const int i = c.x() + o[0], j = c.y() + o[1], k = c.z() + o[2];
            if (i < 0 || j < 0 || k < 0 || i >= nx || j >= ny || k >= nz) continue;
            const int32_t t = tri[shape.index(i, j, k)];
            if (t < 0 || t == next[idx]) continue;
            const auto& f = mesh.triangles[size_t(t)];
            const double e = (closest_point_on_triangle(p, mesh.vertices[f[0]], mesh.vertices[f[1]], mesh.vertices[f[2]]) - p).norm();
            if (e < d[idx]) {
              d[idx] = float(e);
              next[idx] = t;
            }
          }
        }
      });
      tri.swap(next);
    }
    // An open mesh's solid is also bounded across its holes, where there are no triangles:
    // there, bound interior distances by the distance to the solid's outside: every point of
    // the solid's boundary lies within half a voxel diagonal of an outside voxel center.
    if (!stats.defects.watertight()) {
      std::vector<uint8_t> outside(total);
      for (size_t idx = 0; idx < total; ++idx) outside[idx] = !inside[idx];
      const std::vector<int32_t> out_nearest = nearest_seed_transform(shape, outside);
      tbb::parallel_for(tbb::blocked_range<size_t>(0, total, 4096), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t idx = r.begin(); idx != r.end(); ++idx) {
          if (!inside[idx] || out_nearest[idx] < 0) continue;
          const double hole = (shape.world(idx) - shape.world(size_t(out_nearest[idx]))).norm() - 0.5 * std::sqrt(3.0) * h;
          if (hole < d[idx]) d[idx] = float(std::max(hole, 0.0));
          if (tri[idx] < 0) tri[idx] = 0;  // an inside voxel far from any triangle still has a value
        }
      });
      stats.bounded_by_holes = true;
    }
    std::atomic<size_t> interior{0};
    tbb::parallel_for(tbb::blocked_range<size_t>(0, total, 4096), [&](const tbb::blocked_range<size_t>& r) {
      size_t local = 0;
      for (size_t idx = r.begin(); idx != r.end(); ++idx) {
        if (tri[idx] < 0) continue;  // far outside: background
        if (inside[idx]) {
          field.values[idx] = -d[idx];
          ++local;
        } else {
          field.values[idx] = std::min(d[idx], field.background);
        }
      }
      interior += local;
    });
    stats.interior_voxels = interior;
  }
  if (stats.interior_voxels == 0)
    fail_input("", "encloses no volume at this resolution (flat, open with no inside, or thinner than a voxel of " +
                       num(h) + "); try a finer --resolution");
  return result;
}

nlohmann::json SdfStats::to_json() const {
  return {{"defects", defects.to_json()},
          {"sign_method", sign_method},
          {"band_voxels", band_voxels},
          {"interior_voxels", interior_voxels},
          {"winding_evaluations", winding_evaluations},
          {"bounded_by_holes", bounded_by_holes},
          {"estimated_memory_gib", estimated_memory_gib}};
}

}  // namespace spx
