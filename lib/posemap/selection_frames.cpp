// What the joint selection computes over its frames alone: a rest centre's spheres in every
// frame, a set's errors over every frame, and the first round's frames.
#include <algorithm>
#include <cmath>
#include <numeric>

#include "posemap/joint_selection.hpp"

namespace spx {
namespace {

double largest_displacement(const TriMesh& a, const TriMesh& b) {
  double out = 0;
  for (size_t v = 0; v < a.vertices.size(); ++v) out = std::max(out, (a.vertices[v] - b.vertices[v]).squaredNorm());
  return std::sqrt(out);
}

}  // namespace

bool SelectionFrames::spheres_at(const Eigen::Vector3d& rest_center, std::vector<Sphere>& in_frames) const {
  in_frames.resize(frame_count());
  for (size_t f = 0; f < in_frames.size(); ++f) in_frames[f] = spheres_in({Sphere{rest_center, 0}}, f)[0];
  return std::all_of(in_frames.begin(), in_frames.end(), [](const Sphere& s) { return s.radius > 0; });
}

std::vector<SphereSet> spheres_in_frames(const SelectionFrames& frames, const SphereSet& chosen) {
  std::vector<SphereSet> out(frames.frame_count());
  std::vector<Sphere> in_frames;
  for (const Sphere& s : chosen) {
    frames.spheres_at(s.center, in_frames);  // as a move would make it (one that is 0 in some frame too)
    for (size_t f = 0; f < out.size(); ++f) out[f].push_back(in_frames[f]);
  }
  return out;
}

UnionGaps frame_gaps(const SelectionFrames& frames, const std::vector<std::vector<Eigen::Vector3d>>& samples,
                     const SphereSet& chosen) {
  const std::vector<SphereSet> spheres = spheres_in_frames(frames, chosen);
  UnionGaps out;
  for (size_t f = 0; f < spheres.size(); ++f) {
    const UnionGaps g = union_gaps(samples[f], frames.frame_surface(f).vertices.size(), spheres[f]);
    out.max = std::max(out.max, g.max);
    out.largest = std::max(out.largest, g.largest);
    out.median += g.median / double(spheres.size());
  }
  return out;
}

std::vector<size_t> spanning_frames(const SelectionFrames& frames, size_t count) {
  std::vector<const TriMesh*> meshes(frames.frame_count());
  for (size_t f = 0; f < meshes.size(); ++f) meshes[f] = &frames.frame_mesh(f);
  return spanning_frames(meshes, count);
}

std::vector<size_t> spanning_frames(const std::vector<const TriMesh*>& meshes, size_t count) {
  const size_t n = meshes.size();
  std::vector<size_t> taken{0};
  if (n <= count + 1) {
    taken.resize(n);
    std::iota(taken.begin(), taken.end(), size_t(0));
    return taken;
  }
  std::vector<double> apart(n);
  for (size_t f = 0; f < n; ++f) apart[f] = largest_displacement(*meshes[f], *meshes[0]);
  while (taken.size() < count + 1) {
    const size_t next = size_t(std::max_element(apart.begin(), apart.end()) - apart.begin());
    taken.push_back(next);
    for (size_t f = 0; f < n; ++f) apart[f] = std::min(apart[f], largest_displacement(*meshes[f], *meshes[next]));
  }
  std::sort(taken.begin(), taken.end());
  return taken;
}

}  // namespace spx
