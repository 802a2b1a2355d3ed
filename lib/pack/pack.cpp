#include "pack/pack.hpp"

#include <cmath>
#include <queue>

#include "core/error.hpp"

namespace spx {

constexpr double kFieldMargin = 0.1;  // voxels

PackResult pack_spheres(const DenseField& field, const PackOptions& opt, const MeshQuery* mesh, Log& log) {
  const GridShape& shape = field.shape;
  const double h = shape.voxel_size;
  PackResult result;
  PackStats& stats = result.stats;
  if (opt.min_radius < 0 || std::isnan(opt.min_radius)) fail_usage("--min-radius", "must be a positive number");
  stats.min_radius = opt.min_radius > 0 ? opt.min_radius : 1.5 * h;
  stats.max_radius = opt.max_radius;
  if (!(stats.min_radius > 0) || !std::isfinite(stats.min_radius)) fail_usage("--min-radius", "must be a positive number");
  if (!(opt.max_radius > 0) || std::isnan(opt.max_radius)) fail_usage("--max-radius", "must be a positive number");
  if (opt.max_radius < stats.min_radius) fail_usage("--max-radius", "is smaller than the min radius");
  stats.radius_source = mesh ? "mesh" : "field";

  // Deepest first; ties by voxel index so the result does not depend on the heap's history.
  using Entry = std::pair<float, int64_t>;  // (depth, -index)
  std::vector<Entry> entries;
  for (size_t i = 0; i < field.values.size(); ++i)
    if (field.values[i] < 0) entries.emplace_back(-field.values[i], -int64_t(i));
  stats.interior_voxels = entries.size();
  std::priority_queue<Entry> queue(std::less<Entry>(), std::move(entries));
  std::vector<float> work = field.values;

  stats.stop_reason = "no interior voxel left";
  const int nx = shape.dims.x(), ny = shape.dims.y(), nz = shape.dims.z();
  while (!queue.empty()) {
    const auto [depth, neg_index] = queue.top();
    queue.pop();
    const size_t idx = size_t(-neg_index);
    if (work[idx] != -depth) continue;  // cleared by an earlier sphere
    const Eigen::Vector3d center = shape.world(idx);
    // Field distances may exceed the exact ones by a small fraction of a voxel (the interior
    // transform picks the best of nearby candidate triangles): keep spheres safely inside.
    double distance = depth - kFieldMargin * h;
    if (mesh) {
      if (!mesh->inside(center)) {
        ++stats.centers_rejected;
        continue;
      }
      distance = mesh->distance(center);
    }
    const double radius = std::min(opt.max_radius, distance);
    if (radius < stats.min_radius) {
      stats.stop_reason = "next sphere would be smaller than the min radius";
      break;
    }
    result.spheres.push_back({center, radius});
    log.progress("packing", result.spheres.size(), opt.max_spheres);

    // Clear the field inside the sphere so no later center falls in it.
    const Eigen::Vector3i c = shape.coords(idx);
    const int reach = int(std::floor(radius / h));
    const double r2 = (radius / h) * (radius / h);
    for (int i = std::max(0, c.x() - reach); i <= std::min(nx - 1, c.x() + reach); ++i)
      for (int j = std::max(0, c.y() - reach); j <= std::min(ny - 1, c.y() + reach); ++j)
        for (int k = std::max(0, c.z() - reach); k <= std::min(nz - 1, c.z() + reach); ++k) {
          const double di = i - c.x(), dj = j - c.y(), dk = k - c.z();
          if (di * di + dj * dj + dk * dk <= r2) {
            float& v = work[shape.index(i, j, k)];
            if (v < 0) v = 0;
          }
        }
    if (opt.max_spheres > 0 && result.spheres.size() >= opt.max_spheres) {
      stats.stop_reason = "reached the max sphere count";
      break;
    }
  }
  if (!result.spheres.empty()) {
    stats.smallest = stats.largest = result.spheres.front().radius;
    for (const auto& s : result.spheres) {
      stats.smallest = std::min(stats.smallest, s.radius);
      stats.largest = std::max(stats.largest, s.radius);
    }
  }
  return result;
}

nlohmann::json PackStats::to_json() const {
  nlohmann::json j = {{"radius_source", radius_source},   {"stop_reason", stop_reason},
                      {"min_radius", min_radius},         {"smallest_radius", smallest},
                      {"largest_radius", largest},        {"interior_voxels", interior_voxels},
                      {"centers_rejected", centers_rejected}};
  j["max_radius"] = std::isfinite(max_radius) ? nlohmann::json(max_radius) : nlohmann::json(nullptr);
  return j;
}

}  // namespace spx
