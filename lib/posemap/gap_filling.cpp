#include "posemap/gap_filling.hpp"

#include <algorithm>

#include "core/format.hpp"

namespace spx {

PoseGaps pack_pose_gaps(DenseField field, const SphereSet& mapped, const MeshQuery& pose, const PackOptions& pack,
                        double target, size_t max_count, const std::string& source, Log& log) {
  // Not a candidate center where a mapped sphere already covers it.
  for (const auto& s : mapped)
    if (s.radius > 0) clear_inside(field.values, field.shape, s.center, s.radius);
  PackResult found = pack_spheres(field, pack, &pose);
  const TriMesh& surface = pose.surface();
  ToleranceResult enough = fewest_spheres_within(surface, found.spheres, target, mapped);
  if (!enough.met) {
    // Out of reach at this voxel size: keep only the spheres that lower the max error.
    const ToleranceResult best = fewest_spheres_within(surface, found.spheres, enough.max_error * (1 + 1e-9), mapped);
    enough.count = best.count;
  }
  size_t keep = enough.count;
  if (max_count > 0) keep = std::min(keep, max_count);
  found.spheres.resize(keep);
  if (!enough.met)
    log.warn(source + ": gap filling reaches max error " + num(enough.max_error) + ", not the target " + num(target) +
             " (try a finer resolution for the spheres' field)");
  return {std::move(found.spheres), enough.met, enough.max_error};
}

}  // namespace spx
