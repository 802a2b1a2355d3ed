#include <tbb/parallel_for.h>

#include <algorithm>
#include <numeric>

#include "pack/candidates.hpp"
#include "posemap/joint_selector.hpp"

namespace spx {

const std::vector<Eigen::Vector3d>& JointSelector::samples(size_t f) {
  if (samples_[f].empty()) {
    SurfaceSamples drawn = sample_surface(frames_.frame_surface(f), opt_.area_samples, opt_.seed);
    samples_[f] = std::move(drawn.points);
    triangles_[f] = std::move(drawn.triangle);
    held_[f].assign(samples_[f].size(), 0);
    touched_[f].assign(samples_[f].size(), 0);
  }
  return samples_[f];
}

std::vector<std::pair<size_t, std::vector<uint32_t>>> JointSelector::every_vertex_of(
    const std::vector<size_t>& frames) {
  std::vector<std::pair<size_t, std::vector<uint32_t>>> out;
  for (size_t f : frames) out.emplace_back(f, std::vector<uint32_t>(working(f).begin(), working(f).begin() + long(working_vertices(f))));
  return out;
}

std::vector<std::vector<uint32_t>> JointSelector::touch_out_of_reach(
    const std::vector<std::pair<size_t, std::vector<uint32_t>>>& wanting, double delta, bool cached) {
  std::vector<std::vector<uint32_t>> out = out_of_reach_of(wanting, delta, cached);
  if (!touching()) return out;
  // A vertex is offered balls through it once; skinned, one still out of reach is then offered
  // balls around it once (touched_: 1, then 2).
  for (char stage = 0; stage < (one_ ? 2 : 1); ++stage) {
    std::vector<std::pair<size_t, std::vector<uint32_t>>> again;  // (frame, samples) still to ask
    std::vector<size_t> of;                                        // each one's entry in `wanting`
    SphereSet balls;
    for (size_t b = 0; b < wanting.size(); ++b) {
      if (out[b].empty()) continue;
      const size_t f = wanting[b].first;
      std::vector<uint32_t> touch;
      const size_t vertices = vertex_count(f);
      for (uint32_t w : out[b]) {
        const uint32_t i = wanting[b].second[w];
        if (i < vertices && touched_[f][i] == stage) touched_[f][i] = char(stage + 1), touch.push_back(i);
      }
      if (!touch.empty()) {
        const SphereSet more = frames_.touching_candidates(f, {samples_[f], triangles_[f]}, touch, delta, stage == 1);
        balls.insert(balls.end(), more.begin(), more.end());
      }
      again.emplace_back(f, pick(wanting[b].second, out[b]));
      of.push_back(b);
    }
    if (balls.empty()) continue;
    add_candidates(balls);
    balls_offered_[size_t(stage)] += balls.size();
    const std::vector<std::vector<uint32_t>> still = out_of_reach_of(again, delta, cached);
    for (size_t k = 0; k < again.size(); ++k) out[of[k]] = pick(out[of[k]], still[k]);
  }
  return out;
}

void JointSelector::mark_small(const SphereSet& at_rest, size_t count) {
  if (!(opt_.min_radius > 0)) {
    small_.resize(small_.size() + count, 0);
    return;
  }
  for (const Sphere& s : at_rest) {
    const bool small = s.radius > 0 && s.radius < opt_.min_radius;
    small_.push_back(small);
    if (small) note_below_min(s.radius);
  }
}

void JointSelector::withdraw_small(SphereSet& in_frame, size_t first) const {
  for (size_t i = 0; i < in_frame.size(); ++i)
    if (small_[first + i]) in_frame[i].radius = 0;
}

void JointSelector::add_candidates(const SphereSet& more) {
  const size_t first = candidates_.size();
  candidates_.insert(candidates_.end(), more.begin(), more.end());
  if (!one_) {
    // The rest's spheres, asked once: they decide which are smaller than the least radius.
    const SphereSet at_rest = opt_.min_radius > 0 || is_active(0) ? frames_.spheres_in(more, 0) : SphereSet();
    mark_small(at_rest, more.size());
    for (size_t f : active_) {
      SphereSet in = f == 0 ? at_rest : frames_.spheres_in(more, f);
      withdraw_small(in, first);
      own_[f].insert(own_[f].end(), in.begin(), in.end());
    }
    return;
  }
  const SkinnedMap::Carried carried = frames_.carry_skinned(more);
  for (size_t f = 0; f < carried.centers.size(); ++f)
    centers_[f].insert(centers_[f].end(), carried.centers[f].begin(), carried.centers[f].end());
  // Held over the clip before any cover sees them: a cover of radii that hold only at the poses
  // would be undone sphere by sphere, each replaced by another not yet held.
  std::vector<double> held = frames_.over_clip(carried.influences, carried.radii);
  for (size_t i = 0; i < held.size(); ++i) clip_shrunk_ += held[i] < carried.radii[i];
  for (double& r : held) r = at_least_min_radius(r);
  radius_.insert(radius_.end(), held.begin(), held.end());
  checked_.resize(radius_.size(), 0);
}

void JointSelector::select_on_whole(const std::vector<size_t>& more) {
  if (more.empty()) return;
  if (!one_)
    for (size_t f : more) {
      own_[f] = frames_.spheres_in(candidates_, f);
      withdraw_small(own_[f], 0);
    }
  for (size_t f : more) {
    extra_[f].clear();
    held_[f].assign(samples(f).size(), 1);
  }
  active_.insert(active_.end(), more.begin(), more.end());
  std::sort(active_.begin(), active_.end());
  std::vector<std::pair<size_t, std::vector<uint32_t>>> wanting;
  for (size_t f : more) wanting.emplace_back(f, working(f));
  offer_frame_candidates(wanting);
}

void JointSelector::offer_every_frame() {
  std::vector<std::pair<size_t, std::vector<uint32_t>>> wanting;
  for (size_t f = 1; f < frames_.frame_count(); ++f)
    if (!is_active(f)) wanting.emplace_back(f, every_sample(f));
  offer_frame_candidates(wanting, "frames' own candidates");
}

void JointSelector::offer_frame_candidates(const std::vector<std::pair<size_t, std::vector<uint32_t>>>& wanting,
                                           const char* progress) {
  std::vector<std::vector<Eigen::Vector3d>> far(wanting.size());
  // The file's candidates in the frames selected on, those mostly absent withdrawn as in the
  // cover problem (a skinned candidate is absent everywhere or nowhere: other frames need none).
  CoverProblem file_in_active;
  for (size_t f : active_) {
    SphereSet set(file_count_);
    for (size_t c = 0; c < file_count_; ++c) set[c] = sphere(c, f);
    file_in_active.spheres.push_back(std::move(set));
  }
  withdraw_mostly_absent(file_in_active);
  for (const auto& [f, which] : wanting) samples(f);  // drawn once, before the frames run side by side
  tbb::parallel_for(size_t(0), wanting.size(), [&](size_t n) {  // each frame once in `wanting`
    const auto& [f, which] = wanting[n];
    if (f == 0) return;
    const std::vector<Eigen::Vector3d> points = pick(samples_[f], which);
    const size_t k = size_t(std::lower_bound(active_.begin(), active_.end(), f) - active_.begin());
    SphereSet file(file_count_);
    for (size_t c = 0; c < file_count_; ++c) file[c] = is_active(f) ? file_in_active.spheres[k][c] : sphere(c, f);
    std::vector<char>& offered = offered_[f];
    offered.resize(samples_[f].size(), 0);
    for (uint32_t s : bare_samples(points, file, opt_.reach))
      if (!offered[which[s]]) {
        offered[which[s]] = 1;
        far[n].push_back(points[s]);
      }
  });
  for (size_t n = 0; n < wanting.size(); ++n) {
    if (progress) log_.progress(progress, n + 1, wanting.size());
    if (far[n].empty()) continue;
    SphereSet back = frames_.frame_candidates(wanting[n].first, far[n], opt_.reach);
    // Skinned, a clip's alike frames offer much the same spheres again: one per place.
    if (one_ && opt_.spacing > 0) back = pick(back, distinct_centres(candidates_, back, opt_.spacing));
    add_candidates(back);
    from_frames_ += back.size();
  }
}

std::vector<std::vector<uint32_t>> JointSelector::out_of_reach_of(
    const std::vector<std::pair<size_t, std::vector<uint32_t>>>& bare, double delta, bool cached) {
  if (compacting() && cached) {
    if (!(cache_ && cache_->delta() == delta)) cache_ = std::make_unique<CoverageCache>(delta);
    std::vector<std::vector<Eigen::Vector3d>> points;
    for (const auto& [f, which] : bare) points.push_back(pick(samples_[f], which));
    return cache_->uncovered_joining(points, candidates_.size(),
                                     [&](size_t part, size_t c) { return sphere(c, bare[part].first); }, bare);
  }
  std::vector<std::vector<uint32_t>> out(bare.size());
  tbb::parallel_for(size_t(0), bare.size(), [&](size_t b) {  // frame by frame side by side
    const auto& [f, which] = bare[b];
    SphereSet all(candidates_.size());
    for (size_t c = 0; c < all.size(); ++c) all[c] = sphere(c, f);
    out[b] = bare_samples(pick(samples_[f], which), all, delta);
  });
  return out;
}
}  // namespace spx
