#include "posemap/joint_refine.hpp"

#include <algorithm>
#include <numeric>

#include "pack/cover.hpp"

namespace spx {

bool SelectionFrames::spheres_at(const Eigen::Vector3d& rest_center, std::vector<Sphere>& in_frames) const {
  in_frames.resize(frame_count());
  for (size_t f = 0; f < in_frames.size(); ++f) {
    in_frames[f] = spheres_in({Sphere{rest_center, 0}}, f)[0];
    if (!(in_frames[f].radius > 0)) return false;
  }
  return true;
}

size_t refine_chosen(const SelectionFrames& frames, const std::vector<std::vector<Eigen::Vector3d>>& samples,
                     double step, SphereSet& chosen, double delta, Log& log) {
  const size_t count = frames.frame_count();
  std::vector<size_t> weighted(count);
  std::vector<SphereSet> spheres(count);
  std::vector<Eigen::Vector3d> centers;
  for (const Sphere& s : chosen) centers.push_back(s.center);
  for (size_t f = 0; f < count; ++f) {
    weighted[f] = frames.frame_surface(f).vertices.size();
    if (!frames.one_radius()) spheres[f] = frames.spheres_in(chosen, f);
  }
  // Skinned, each sphere as spheres_at makes it: its one radius in every frame.
  std::vector<Sphere> in_frames;
  for (size_t s = 0; s < chosen.size() && frames.one_radius(); ++s) {
    if (!frames.spheres_at(chosen[s].center, in_frames)) return 0;  // a radius 0 somewhere: left as chosen
    for (size_t f = 0; f < count; ++f) spheres[f].push_back(in_frames[f]);
  }
  const PoseSpheresAt at = [&](const Eigen::Vector3d& c, std::vector<Sphere>& out) { return frames.spheres_at(c, out); };
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
