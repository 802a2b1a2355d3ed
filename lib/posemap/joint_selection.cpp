#include "posemap/joint_selection.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <limits>
#include <memory>
#include <numeric>

#include "core/format.hpp"
#include "pack/candidates.hpp"
#include "pack/coverage.hpp"
#include "pack/set_cover.hpp"
#include "posemap/joint_refine.hpp"

namespace spx {
namespace {

// A check adds, besides the samples the chosen spheres leave bare, those they cover by less than
// this share of delta: the next cover, free to move its spheres, would leave them bare.
constexpr double kNearlyBare = 0.5;
// Where the problem is compacted each round a round costs little, and the check adds only those
// covered by less than this share: on 48 frames of the elephant's walk a quarter as many samples
// over more rounds, in less time and memory, and no more spheres.
constexpr double kNearlyBareCompacted = 0.75;

// Budget mode checks the other frames once: each round is a whole budget cover (a bisection over
// tables of pairs), and on a long clip every cover leaves a few samples of some other frame past
// its delta (48 frames of the elephant's walk at 64 spheres: a round of about half a minute, a
// dozen rounds and more). What the second round's cover leaves past its delta the refinement,
// which weighs every frame's samples, takes on; every frame's error is in the report.
constexpr size_t kBudgetRounds = 2;

template <class T, class Index>
std::vector<T> pick(const std::vector<T>& all, const std::vector<Index>& which) {
  std::vector<T> out;
  out.reserve(which.size());
  for (Index i : which) out.push_back(all[size_t(i)]);
  return out;
}

// The selection's state as it grows: the candidates (rest), the frames selected on whole, each
// candidate's sphere there (not skinned) or its centre in every frame and its one radius
// (skinned), and the samples of other frames added (skinned).
class Selector {
 public:
  Selector(SelectionFrames& frames, const JointSelectionOptions& opt, Log& log)
      : frames_(frames),
        opt_(opt),
        log_(log),
        one_(frames.one_radius()),
        own_(frames.frame_count()),
        samples_(frames.frame_count()),
        offered_(frames.frame_count()),
        extra_(frames.frame_count()),
        held_(frames.frame_count()),
        centers_(one_ ? frames.frame_count() : 0) {}

  JointSelection run(const SphereSet& file_candidates) {
    JointSelection out;
    file_count_ = file_candidates.size();
    add_candidates(file_candidates);
    select_on_whole(spanning_frames(frames_, opt_.first_frames));
    if (one_) offer_every_frame();
    for (;;) {
      ++out.rounds;
      const bool warm = out.rounds > 1 && opt_.budget == 0;
      // Skinned, a warm round's pairs come from the cache, which asks for the few spheres it needs.
      const CoverProblem problem = cover_problem(out.mostly_absent, !(warm && one_));
      if (warm)
        warm_cover(problem, out.cover);
      else
        out.cover = cover_for(problem, opt_.target, opt_.budget, out.limited_by, log_,
                              refining() ? kRefinedBudgetSlack : kBudgetSlack);
      // A radius the check lowers was counted on as larger: cover the same problem again.
      if (one_ && lower_unchecked_radii(out.cover.chosen, out)) continue;
      std::vector<int> order = out.cover.chosen;
      // Largest first by the rest sphere each becomes, as sphere-pack orders its spheres.
      std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
        return rest_radius(problem, a) > rest_radius(problem, b);
      });
      out.chosen = pick(candidates_, order);
      if (one_)
        for (size_t n = 0; n < order.size(); ++n) out.chosen[n].radius = radius_[size_t(order[n])];
      out.samples = problem.sample_count();
      size_t more_samples = 0;
      std::vector<size_t> more_frames;
      if (active_.size() < frames_.frame_count() && (opt_.budget == 0 || out.rounds < kBudgetRounds)) {
        if (one_)
          more_samples = add_bare_samples(out.cover.chosen, out.cover.delta, out.bare_elsewhere,
                                          compacting() ? &out.cover.kept_samples : nullptr);
        else
          more_frames = frames_left_bare(out.cover.chosen, out.cover.delta);
      }
      log_.detail("joint selection, round " + std::to_string(out.rounds) + ": " + std::to_string(out.chosen.size()) +
                  " spheres selected on " + std::to_string(active_.size()) + " of " +
                  std::to_string(frames_.frame_count()) + " frames and " + std::to_string(samples_elsewhere()) +
                  " samples of the others; then " + std::to_string(more_samples) + " more samples, " +
                  std::to_string(more_frames.size()) + " more frames");
      if (more_samples == 0 && more_frames.empty()) break;
      select_on_whole(more_frames);
    }
    // What decided the size is the last round's: samples of other frames out of reach, or reached
    // only after the first round, change whether the tolerance was met (cover_for's rule).
    if (out.limited_by == Limit::tolerance || out.limited_by == Limit::resolution)
      out.limited_by = out.cover.uncoverable + out.bare_elsewhere > 0 ? Limit::resolution : Limit::tolerance;
    if (refining()) {
      out.refined_moves = refine(out.chosen, out.cover.delta);
      polish(out);
    }
    out.candidates = candidates_.size();
    out.from_frames = from_frames_;
    out.frames = active_;
    out.samples_elsewhere = samples_elsewhere();
    out.clip_shrunk = clip_shrunk_;
    return out;
  }

 private:
  bool is_active(size_t f) const { return std::binary_search(active_.begin(), active_.end(), f); }

  // Budget mode: the chosen centres are refined off the candidates (below).
  bool refining() const { return opt_.budget > 0 && opt_.refine_step > 0; }
  size_t refine(SphereSet& chosen, double delta) {
    for (size_t f = 0; f < frames_.frame_count(); ++f) samples(f);  // over every frame, as drawn here
    return refine_chosen(frames_, samples_, opt_.refine_step, chosen, delta, log_);
  }

  // Budget mode, opt_.polish_rounds times: the last refined set joins the candidates, the budget
  // is covered again from the delta where that set is a cover (the problem's largest gap to it),
  // and the cover is refined over every frame; the best set by kept_over on every frame's
  // samples (the worst frame's max, the frames' mean median) is kept, its cover with it. After
  // the refinement, which drew every frame's samples.
  void polish(JointSelection& out) {
    out.polish_rounds = opt_.polish_rounds;
    if (opt_.polish_rounds <= 0) return;  // no set to weigh the first refinement's against
    SphereSet current = out.chosen;
    UnionGaps best = frame_gaps(frames_, samples_, current);
    for (int round = 1; round <= opt_.polish_rounds; ++round) {
      const size_t first = candidates_.size();
      add_candidates(current);
      size_t withdrawn = 0;
      CoverProblem problem = cover_problem(withdrawn, true);
      const double start = largest_gap_to(problem, first, current.size());
      CoverResult cover = cover_with_budget(problem, opt_.budget, kRefinedBudgetSlack, 1e-2, log_, start);
      // A radius the check lowers was counted on as larger: cover the same problem again.
      while (one_ && lower_unchecked_radii(cover.chosen, out)) {
        problem = cover_problem(withdrawn, true);
        cover = cover_with_budget(problem, opt_.budget, kRefinedBudgetSlack, 1e-2, log_, start);
      }
      current = pick(candidates_, cover.chosen);
      if (one_)
        for (size_t n = 0; n < current.size(); ++n) current[n].radius = radius_[size_t(cover.chosen[n])];
      const size_t moves = refine(current, cover.delta);
      const UnionGaps now = frame_gaps(frames_, samples_, current);
      log_.detail("polish " + std::to_string(round) + ": worst frame's vertex error max " + num(now.max) +
                  ", mean median " + num(now.median) + " (kept so far: " + num(best.max) + ", " + num(best.median) + ")");
      if (!kept_over(now, best)) continue;
      best = now;
      out.chosen = current;
      out.cover = std::move(cover);
      out.refined_moves = moves;
      out.polished = size_t(round);
    }
  }

  // Skinned: the share of delta past which a check adds a sample. Budget mode adds only the bare:
  // its delta is the least the budget reaches, so most samples are covered by more than half of
  // it, the nearly bare would be nearly every sample of the clip, and each round's budget cover
  // (tables of every pair within delta) grows with them (48 frames of the elephant's walk at 64
  // spheres took over 20 GB).
  double nearly_bare() const { return opt_.budget > 0 ? 1.0 : compacting() ? kNearlyBareCompacted : kNearlyBare; }

  // Skinned, tolerance: after each round the problem keeps only the samples its reduction kept
  // (a cover of those covers the rest), so that a round costs what the hard samples of the clip
  // cost, not what all its frames do. The candidates stay (each frame's were offered up front).
  bool compacting() const { return one_ && opt_.budget == 0; }

  // The reduction's kept samples (stacked indices of the last problem) by frame.
  std::vector<std::vector<uint32_t>> kept_by_frame(const std::vector<uint32_t>& kept) const {
    std::vector<std::vector<uint32_t>> out(frames_.frame_count());
    size_t part = 0, first = 0;
    for (uint32_t s : kept) {
      while (s >= first + layout_[part].second.size()) first += layout_[part++].second.size();
      out[layout_[part].first].push_back(layout_[part].second[s - first]);
    }
    for (auto& list : out) std::sort(list.begin(), list.end());
    return out;
  }

  size_t samples_elsewhere() const {
    size_t n = 0;
    for (size_t f = 0; f < extra_.size(); ++f) n += is_active(f) ? 0 : extra_[f].size();
    return n;
  }

  const std::vector<Eigen::Vector3d>& samples(size_t f) {
    if (samples_[f].empty()) {
      samples_[f] = surface_samples(frames_.frame_surface(f), opt_.area_samples, opt_.seed);
      held_[f].assign(samples_[f].size(), 0);
    }
    return samples_[f];
  }

  std::vector<uint32_t> every_sample(size_t f) {
    std::vector<uint32_t> out(samples(f).size());
    std::iota(out.begin(), out.end(), 0u);
    return out;
  }

  // Candidate c in frame f as the problem has it.
  Sphere sphere(size_t c, size_t f) const { return one_ ? Sphere{centers_[f][c], radius_[c]} : own_[f][c]; }

  // Tolerance mode, after the first round: the last cover completed for what was added, then
  // searched briefly, so that it stays near the last one and the next check finds little new.
  void warm_cover(const CoverProblem& problem, CoverResult& cover) {
    // Skinned, a round's samples are mostly the last one's, and its candidates only grow: their
    // pairs are kept (a radius the check lowers clears them; one radius for every frame, so a
    // candidate is never withdrawn in some rounds and not others).
    if (one_ && !(cache_ && cache_->delta() == cover.delta)) cache_ = std::make_unique<CoverageCache>(cover.delta);
    const Coverage coverage =
        one_ ? cache_->coverage(problem.samples, candidates_.size(),
                                [&](size_t part, size_t c) { return sphere(c, layout_[part].first); }, layout_)
             : coverage_at(problem, cover.delta);
    cover.chosen = smallest_cover(coverage, kWarmSearch, 0, nullptr, log_, cover.chosen, &cover.kept_samples);
    cover.uncoverable = uncovered_samples(coverage).size();
  }

  // Skinned: each chosen candidate's one radius, not checked before, checked against its exact
  // radius in every frame (the carry skips frames by their fields' floors, which may be a
  // fraction of a voxel high). Returns whether any was lowered.
  bool lower_unchecked_radii(const std::vector<int>& chosen, JointSelection& out) {
    std::vector<size_t> unchecked;
    for (int c : chosen)
      if (!checked_[size_t(c)]) unchecked.push_back(size_t(c));
    std::vector<double> least(unchecked.size());
    tbb::parallel_for(size_t(0), unchecked.size(), [&](size_t n) {
      const size_t c = unchecked[n];
      least[n] = radius_[c];
      for (size_t f = 0; f < frames_.frame_count() && least[n] > 0; ++f)
        least[n] = std::min(least[n], frames_.exact_radius(centers_[f][c], f));
    });
    size_t lowered = 0;
    for (size_t n = 0; n < unchecked.size(); ++n) {
      checked_[unchecked[n]] = 1;
      lowered += least[n] < radius_[unchecked[n]];
      radius_[unchecked[n]] = least[n];
    }
    out.radii_checked += unchecked.size();
    out.radii_lowered += lowered;
    if (lowered > 0 && cache_) cache_->clear();
    return lowered > 0;
  }

  // More candidates: their spheres in the frames selected on or, skinned, their centres in every
  // frame and their one radius.
  void add_candidates(const SphereSet& more) {
    candidates_.insert(candidates_.end(), more.begin(), more.end());
    if (!one_) {
      for (size_t f : active_) {
        const SphereSet in = frames_.spheres_in(more, f);
        own_[f].insert(own_[f].end(), in.begin(), in.end());
      }
      return;
    }
    const SkinnedMap::Carried carried = frames_.carry_skinned(more);
    for (size_t f = 0; f < carried.centers.size(); ++f)
      centers_[f].insert(centers_[f].end(), carried.centers[f].begin(), carried.centers[f].end());
    // Held over the clip before any cover sees them: a cover of radii that hold only at the poses
    // would be undone sphere by sphere, each replaced by another not yet held.
    const std::vector<double> held = frames_.over_clip(carried.influences, carried.radii);
    for (size_t i = 0; i < held.size(); ++i) clip_shrunk_ += held[i] < carried.radii[i];
    radius_.insert(radius_.end(), held.begin(), held.end());
    checked_.resize(radius_.size(), 0);
  }

  // Frames `more` are selected on whole: every candidate mapped there (not skinned), and their
  // samples no candidate of the spheres file comes within reach of are offered their own
  // candidates.
  void select_on_whole(const std::vector<size_t>& more) {
    if (more.empty()) return;
    if (!one_)
      for (size_t f : more) own_[f] = frames_.spheres_in(candidates_, f);
    for (size_t f : more) {
      extra_[f].clear();
      held_[f].assign(samples(f).size(), 1);
    }
    active_.insert(active_.end(), more.begin(), more.end());
    std::sort(active_.begin(), active_.end());
    std::vector<std::pair<size_t, std::vector<uint32_t>>> wanting;
    for (size_t f : more) wanting.emplace_back(f, every_sample(f));
    offer_frame_candidates(wanting);
  }

  // Skinned: every frame's samples far from the spheres file's candidates are offered that
  // frame's own (what the one cover over every frame would be offered).
  void offer_every_frame() {
    std::vector<std::pair<size_t, std::vector<uint32_t>>> wanting;
    for (size_t f = 1; f < frames_.frame_count(); ++f)
      if (!is_active(f)) wanting.emplace_back(f, every_sample(f));
    offer_frame_candidates(wanting);
  }

  // Of each frame's samples `which`, those no candidate of the spheres file comes within reach
  // of (and not offered before) are offered that frame's own candidates near them: every
  // frame's far samples found first, then the pool grows frame by frame.
  void offer_frame_candidates(const std::vector<std::pair<size_t, std::vector<uint32_t>>>& wanting) {
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
      if (far[n].empty()) continue;
      SphereSet back = frames_.frame_candidates(wanting[n].first, far[n], opt_.reach);
      // Skinned, a clip's alike frames offer much the same spheres again: one per place.
      if (one_ && opt_.spacing > 0) back = pick(back, distinct_centres(candidates_, back, opt_.spacing));
      add_candidates(back);
      from_frames_ += back.size();
    }
  }

  // Candidate c's radius in the rest (skinned: its one radius; a problem of samples alone has no
  // spheres).
  double rest_radius(const CoverProblem& problem, int c) const {
    return one_ ? radius_[size_t(c)] : problem.spheres[0][size_t(c)].radius;
  }

  // The frames selected on, whole, then (skinned) the samples added from the others, as one
  // cover problem. Candidates mostly absent are withdrawn (counted). Without `spheres`, the
  // samples alone (a skinned candidate is absent in every frame or in none: none is withdrawn).
  CoverProblem cover_problem(size_t& mostly_absent, bool spheres) {
    CoverProblem p;
    layout_.clear();
    auto add = [&](size_t f, std::vector<uint32_t> which, size_t weighted) {
      p.samples.push_back(pick(samples(f), which));
      layout_.emplace_back(f, std::move(which));
      p.weighted.push_back(weighted);
      if (!spheres) return;
      SphereSet set(candidates_.size());
      for (size_t c = 0; c < set.size(); ++c) set[c] = sphere(c, f);
      p.spheres.push_back(std::move(set));
    };
    if (whole_)
      for (size_t f : active_) add(f, every_sample(f), frames_.frame_surface(f).vertices.size());
    for (size_t f = 0; f < extra_.size(); ++f)
      if (!extra_[f].empty()) add(f, extra_[f], 0);
    mostly_absent = spheres ? withdraw_mostly_absent(p) : 0;
    return p;
  }

  // Skinned: the samples the chosen spheres leave bare, or cover by less than kNearlyBare of
  // delta, that the problem does not hold (one it held before only if bare outright). Those far
  // from the spheres file's candidates are offered their frame's own first; then those some
  // candidate reaches join the problem, the rest are counted in `bare_elsewhere`. `kept`
  // (compacting): the samples the last problem's reduction kept; the problem becomes those and
  // the samples joining. Returns how many joined.
  size_t add_bare_samples(const std::vector<int>& chosen, double delta, size_t& bare_elsewhere,
                          const std::vector<uint32_t>* kept) {
    const size_t frames = frames_.frame_count();
    for (size_t f = 0; f < frames; ++f) samples(f);  // drawn once, before the frames run side by side
    std::vector<std::vector<uint32_t>> wanting(frames);
    tbb::parallel_for(size_t(0), frames, [&](size_t f) {
      if (whole_ && is_active(f)) return;
      SphereSet spheres(chosen.size());
      for (size_t s = 0; s < chosen.size(); ++s) spheres[s] = sphere(size_t(chosen[s]), f);
      const std::vector<uint32_t> nearly = bare_samples(samples_[f], spheres, nearly_bare() * delta);
      // Of those, the bare outright: a scan of the few, not of every sample again.
      const std::vector<uint32_t> outright = bare_samples(pick(samples_[f], nearly), spheres, delta);
      for (size_t n = 0, o = 0; n < nearly.size(); ++n) {
        const uint32_t b = nearly[n];
        const bool is_outright = o < outright.size() && outright[o] == n;
        o += is_outright;
        if (!std::binary_search(extra_[f].begin(), extra_[f].end(), b) && (!held_[f][b] || is_outright))
          wanting[f].push_back(b);
      }
    });
    std::vector<std::pair<size_t, std::vector<uint32_t>>> bare;
    for (size_t f = 0; f < frames; ++f)
      if (!wanting[f].empty()) bare.emplace_back(f, std::move(wanting[f]));
    offer_frame_candidates(bare);
    const std::vector<std::vector<uint32_t>> out_of_reach = out_of_reach_of(bare, delta);
    std::vector<std::vector<uint32_t>> joining(frames);
    size_t added = 0;
    bare_elsewhere = 0;
    for (size_t b = 0; b < bare.size(); ++b) {
      const auto& [f, which] = bare[b];
      const std::vector<uint32_t>& out_of_reach_here = out_of_reach[b];
      bare_elsewhere += out_of_reach_here.size();
      for (size_t w = 0, o = 0; w < which.size(); ++w) {
        if (o < out_of_reach_here.size() && out_of_reach_here[o] == w) {
          ++o;
          continue;
        }
        joining[f].push_back(which[w]);
        held_[f][which[w]] = 1;
        ++added;
      }
    }
    if (added == 0) return 0;
    if (kept) {
      whole_ = false;
      extra_ = kept_by_frame(*kept);
    }
    for (size_t f = 0; f < extra_.size(); ++f) {
      extra_[f].insert(extra_[f].end(), joining[f].begin(), joining[f].end());
      std::sort(extra_[f].begin(), extra_[f].end());
    }
    return added;
  }

  // Of each frame's samples `which`, the positions of those no candidate reaches. Compacting, the
  // cache finds them: the columns it computes are those the next round's problem asks for.
  std::vector<std::vector<uint32_t>> out_of_reach_of(const std::vector<std::pair<size_t, std::vector<uint32_t>>>& bare,
                                                     double delta) {
    if (compacting()) {
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

  // Not skinned: the frames not selected on where the chosen spheres (grown there) leave
  // samples bare, the most first, at most frames_per_round.
  std::vector<size_t> frames_left_bare(const std::vector<int>& chosen, double delta) {
    const SphereSet rest = pick(candidates_, chosen);
    std::vector<std::pair<size_t, size_t>> bare;  // (count, frame)
    for (size_t f = 0; f < frames_.frame_count(); ++f) {
      if (is_active(f)) continue;
      const size_t n = bare_samples(samples(f), frames_.spheres_in(rest, f), delta).size();
      if (n > 0) bare.emplace_back(n, f);
    }
    std::stable_sort(bare.begin(), bare.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
    std::vector<size_t> out;
    for (size_t n = 0; n < bare.size() && n < opt_.frames_per_round; ++n) out.push_back(bare[n].second);
    std::sort(out.begin(), out.end());
    return out;
  }

  SelectionFrames& frames_;
  const JointSelectionOptions& opt_;
  Log& log_;
  const bool one_;                                     // skinned: one radius per sphere
  SphereSet candidates_;                               // rest pose
  std::vector<size_t> active_;                         // frames selected on whole, ascending
  std::vector<SphereSet> own_;                         // not skinned, per frame selected on: each candidate's sphere
  std::vector<std::vector<Eigen::Vector3d>> samples_;  // per frame, drawn when first asked
  std::vector<std::vector<char>> offered_;             // per frame and sample: its frame's candidates offered
  std::vector<std::vector<uint32_t>> extra_;           // skinned, per frame not whole: its samples in the problem
  std::vector<std::vector<char>> held_;                // per frame and sample: it has been in the problem
  bool whole_ = true;                                  // the frames selected on are whole in the problem
  std::vector<std::pair<size_t, std::vector<uint32_t>>> layout_;  // the last problem's samples: (frame, which)
  std::vector<std::vector<Eigen::Vector3d>> centers_;  // skinned, per frame: each candidate's centre there
  std::vector<double> radius_;                         // skinned: each candidate's one radius
  std::vector<char> checked_;                          // skinned: its radius checked in every frame
  std::unique_ptr<CoverageCache> cache_;              // skinned, tolerance: the pairs kept from round to round
  size_t from_frames_ = 0;
  size_t clip_shrunk_ = 0;  // skinned: candidates whose radius the clip lowered
  size_t file_count_ = 0;  // the candidates [0, file_count_) are the spheres file's
};

}  // namespace

JointSelection select_jointly(SelectionFrames& frames, const SphereSet& candidates, const JointSelectionOptions& options,
                              Log& log) {
  return Selector(frames, options, log).run(candidates);
}

}  // namespace spx
