#include "pack/pack.hpp"

#include <cmath>
#include <queue>

#include "core/error.hpp"
#include "core/format.hpp"
#include "core/tolerance.hpp"
#include "mesh/union_distance.hpp"

namespace spx {

nlohmann::json warn_tiny_spheres(const std::vector<double>& radii, double diagonal, const std::string& where, Log& log) {
  const double below = kTinyRadiusShare * diagonal;
  size_t tiny = 0, positive = 0;
  double least = below;
  for (double r : radii)
    if (r > 0) ++positive, tiny += r < below, least = std::min(least, r);
  if (tiny > 0) {
    const bool one = tiny == 1;
    log.warn(std::to_string(tiny) + " of the " + std::to_string(positive) + " spheres " + (one ? "is" : "are") +
             " under " + num(100 * kTinyRadiusShare) + "% of the diagonal (down to " + num(least) + "): " +
             (one ? "a sharp tip's or a fold's own ball" : "sharp tips' or folds' own balls") +
             ", too small for a host to collide with; " + (where.empty() ? "" : where + " ") +
             "--min-radius keeps them out (the tolerance may then be missed at those tips)");
  }
  return {{"count", tiny}, {"below", below}};
}

void check_radius_limits(const PackOptions& opt, double default_min_radius) {
  if (opt.min_radius < 0 || !std::isfinite(opt.min_radius)) fail_option("min_radius", "must be a positive number");
  if (!(opt.max_radius > 0) || std::isnan(opt.max_radius)) fail_option("max_radius", "must be a positive number");
  const double min_radius = opt.min_radius > 0 ? opt.min_radius : default_min_radius;
  if (opt.max_radius < min_radius) fail_option("max_radius", "is smaller than the min radius");
}

PackResult pack_spheres(const DenseField& field, const PackOptions& opt, const MeshQuery* mesh, Log& log) {
  const GridShape& shape = field.shape;
  const double h = shape.voxel_size;
  PackResult result;
  PackStats& stats = result.stats;
  check_radius_limits(opt, 1.5 * h);
  stats.min_radius = opt.min_radius > 0 ? opt.min_radius : 1.5 * h;
  stats.max_radius = opt.max_radius;
  stats.radius_source = mesh ? "mesh" : "field";

  // Deepest first; ties by voxel index so the result does not depend on the heap's history.
  using Entry = std::pair<float, int64_t>;  // (depth, -index)
  std::vector<Entry> entries;
  for (size_t i = 0; i < field.values.size(); ++i)
    if (field.values[i] < 0) entries.emplace_back(-field.values[i], -int64_t(i));
  stats.interior_voxels = entries.size();
  std::priority_queue<Entry> queue(std::less<Entry>(), std::move(entries));
  GridVector<float> work = field.values;

  stats.stop_reason = "no interior voxel left";
  while (!queue.empty()) {
    const auto [depth, neg_index] = queue.top();
    queue.pop();
    const size_t idx = size_t(-neg_index);
    if (work[idx] != -depth) continue;  // cleared by an earlier sphere
    Eigen::Vector3d center = shape.world(idx);
    // Field distances may exceed the exact ones by a small fraction of a voxel (the interior
    // transform picks the best of nearby candidate triangles): keep spheres safely inside.
    double distance = depth - kFieldMargin * h;
    if (mesh) {
      if (!mesh->inside(center)) {
        ++stats.centers_rejected;
        continue;
      }
      distance = mesh->distance(center);
      if (opt.field_bounds_radius) distance = std::min(distance, double(depth) - kFieldMargin * h);
      if (opt.refine_centers && !opt.field_bounds_radius) {
        // Ascend the exact distance (its gradient points away from the closest surface point),
        // staying within half a voxel of the voxel the field chose.
        const Eigen::Vector3d origin = center;
        for (int step = 0; step < 6; ++step) {
          const ClosestPoint c = mesh->closest(center);
          if (!(c.distance > 0)) break;
          Eigen::Vector3d next = center + 0.25 * h * (center - c.point) / c.distance;
          next = origin + (next - origin).cwiseMax(-0.5 * h).cwiseMin(0.5 * h);
          const double d = mesh->distance(next);
          if (!(d > distance) || !mesh->inside(next)) break;
          center = next;
          distance = d;
        }
        if (center != origin) ++stats.centers_refined;
      }
    }
    const double radius = std::min(opt.max_radius, distance);
    if (radius < stats.min_radius) {
      stats.stop_reason = "next sphere would be smaller than the min radius";
      break;
    }
    result.spheres.push_back({center, radius});
    log.progress("packing", result.spheres.size(), opt.max_spheres);

    clear_inside(work, shape, center, radius);  // no later center falls in it
    if (opt.max_spheres > 0 && result.spheres.size() >= opt.max_spheres) {
      stats.stop_reason = "reached the max sphere count";
      break;
    }
  }
  stats.set_radius_range(result.spheres);
  return result;
}

void PackStats::set_radius_range(const SphereSet& spheres) {
  if (spheres.empty()) return;
  smallest = largest = spheres.front().radius;
  for (const auto& s : spheres) {
    smallest = std::min(smallest, s.radius);
    largest = std::max(largest, s.radius);
  }
}

void clear_inside(GridVector<float>& values, const GridShape& shape, const Eigen::Vector3d& center, double radius) {
  const double h = shape.voxel_size;
  const int nx = shape.dims.x(), ny = shape.dims.y(), nz = shape.dims.z();
  const Eigen::Vector3i c = ((center / h).array().round().cast<int>() - shape.origin.array()).matrix();
  const int reach = int(std::floor(radius / h));
  const double r2 = (radius / h) * (radius / h);
  const Eigen::Vector3d cg = center / h - shape.origin.cast<double>();  // center in grid units
  for (int i = std::max(0, c.x() - reach - 1); i <= std::min(nx - 1, c.x() + reach + 1); ++i)
    for (int j = std::max(0, c.y() - reach - 1); j <= std::min(ny - 1, c.y() + reach + 1); ++j)
      for (int k = std::max(0, c.z() - reach - 1); k <= std::min(nz - 1, c.z() + reach + 1); ++k) {
        const double di = i - cg.x(), dj = j - cg.y(), dk = k - cg.z();
        if (di * di + dj * dj + dk * dk <= r2) {
          float& v = values[shape.index(i, j, k)];
          if (v < 0) v = 0;
        }
      }
}

ToleranceResult fewest_spheres_within(const TriMesh& mesh, const SphereSet& sequence, double tolerance,
                                      const SphereSet& base) {
  ToleranceResult r;
  std::vector<double> d(mesh.vertices.size(), std::numeric_limits<double>::infinity());
  if (!base.empty()) {
    d = union_signed_distance(mesh.vertices, base);
    double worst = 0;
    for (double v : d) worst = std::max(worst, std::abs(v));
    if (worst <= tolerance) {
      r.met = true;
      r.max_error = worst;
      return r;
    }
  }
  for (size_t k = 0; k < sequence.size(); ++k) {
    const Sphere& s = sequence[k];
    double worst = 0;
    for (size_t v = 0; v < d.size(); ++v) {
      d[v] = std::min(d[v], (mesh.vertices[v] - s.center).norm() - s.radius);
      worst = std::max(worst, std::abs(d[v]));
    }
    r.max_error_by_count.push_back(worst);
    if (worst <= tolerance) {
      r.met = true;
      r.count = k + 1;
      r.max_error = worst;
      break;
    }
  }
  if (!r.met) {
    r.count = sequence.size();
    r.max_error = r.max_error_by_count.empty() ? std::numeric_limits<double>::infinity() : r.max_error_by_count.back();
  }
  return r;
}

nlohmann::json PackStats::to_json() const {
  nlohmann::json j = {{"radius_source", radius_source},   {"stop_reason", stop_reason},
                      {"min_radius", min_radius},         {"smallest_radius", smallest},
                      {"largest_radius", largest},        {"interior_voxels", interior_voxels},
                      {"centers_rejected", centers_rejected},
                      {"centers_refined", centers_refined}};
  j["max_radius"] = std::isfinite(max_radius) ? nlohmann::json(max_radius) : nlohmann::json(nullptr);
  return j;
}

}  // namespace spx
