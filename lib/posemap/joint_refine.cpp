#include "posemap/joint_refine.hpp"

#include <algorithm>
#include <numeric>

#include "pack/cover.hpp"

namespace spx {

size_t refine_chosen(const SelectionFrames& frames, const std::vector<std::vector<Eigen::Vector3d>>& samples,
                     double step, double min_radius, SphereSet& chosen, double delta, Log& log) {
  const size_t count = frames.frame_count();
  std::vector<size_t> weighted(count);
  std::vector<Eigen::Vector3d> centers;
  for (const Sphere& s : chosen) centers.push_back(s.center);
  for (size_t f = 0; f < count; ++f) weighted[f] = frames.frame_surface(f).vertices.size();
  std::vector<SphereSet> spheres = spheres_in_frames(frames, chosen);
  // No move to where the rest sphere (skinned: the one radius) is smaller than min_radius.
  const PoseSpheresAt at = [&](const Eigen::Vector3d& c, std::vector<Sphere>& out) {
    return frames.spheres_at(c, out) && !(out[0].radius < min_radius);
  };
  const size_t moves = refine_jointly(samples, weighted, centers, spheres, at, delta, step, log, true);
  std::vector<size_t> order(chosen.size());
  std::iota(order.begin(), order.end(), size_t(0));
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return spheres[0][a].radius > spheres[0][b].radius; });
  SphereSet out;
  for (size_t n : order) out.push_back({centers[n], spheres[0][n].radius});
  chosen = std::move(out);
  return moves;
}

}  // namespace spx
