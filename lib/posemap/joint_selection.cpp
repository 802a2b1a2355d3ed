#include "posemap/joint_selector.hpp"

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
// A spaced frame's check adds the vertices covered by less than this share of delta: on the
// elephant split 64-fold with its 4 poses (386 000 vertices a pose, at 2 %) 9 837 vertices over
// 3 rounds in 38.9 s, where the bare alone joined 122 over 7 rounds (a few each) in 49.3 s.
constexpr double kNearlyBareSpaced = 0.9;

// Budget mode checks the other frames once: each round is a whole budget cover (a bisection over
// tables of pairs), and on a long clip every cover leaves a few samples of some other frame past
// its delta (48 frames of the elephant's walk at 64 spheres: a round of about half a minute, a
// dozen rounds and more). What the second round's cover leaves past its delta the refinement,
// which weighs every frame's samples, takes on; every frame's error is in the report.
constexpr size_t kBudgetRounds = 2;

}  // namespace

double JointSelector::nearly_bare() const {
  return opt_.budget > 0 ? 1.0 : compacting() ? kNearlyBareCompacted : kNearlyBare;
}

JointSelection JointSelector::run(const SphereSet& file_candidates) {
  JointSelection out;
  file_count_ = file_candidates.size();
  add_candidates(file_candidates);
  select_on_whole(spanning_frames(frames_, opt_.first_frames));
  if (one_) offer_every_frame();
  if (touching()) touch_out_of_reach(every_vertex_of(active_), opt_.target, false);
  size_t lowered_in_a_row = 0;
  for (;;) {
    ++out.rounds;
    const bool warm = out.rounds > 1 && opt_.budget == 0;
    // Skinned, a warm round's pairs come from the cache, which asks for the few spheres it needs.
    const CoverProblem problem = cover_problem(out.mostly_absent, !(warm && one_));
    cover_round(problem, warm, out);
    // Not skinned, the vertices out of reach (where the tolerance is asked) as near as the
    // candidates come. (A skinned candidate's spheres in a warm round are the cache's alone.)
    if (!one_)
      out.out_of_reach_added =
          cover_out_of_reach(problem, vertices_in(out.cover.uncovered), out.cover.chosen, &out.out_of_reach_delta);
    // A radius the check lowers was counted on as larger: cover the same problem again.
    if (one_ && chosen_radius_lowered(out, lowered_in_a_row)) continue;
    take_chosen(problem, out);
    size_t more_samples = 0;
    std::vector<size_t> more_frames;
    if (active_.size() < frames_.frame_count() && (opt_.budget == 0 || out.rounds < kBudgetRounds)) {
      if (one_)
        more_samples =
            add_bare_samples(out.cover.chosen, out.cover.delta, out, compacting() ? &out.cover.kept_samples : nullptr);
      else
        more_frames = frames_left_bare(out.cover.chosen, out.cover.delta);
    }
    // Every frame the cover should hold in is in it: the vertices its frames left out are checked.
    // (Once compacted, add_bare_samples above reads every sample of every frame, theirs too.)
    if (whole_ && more_samples == 0 && more_frames.empty())
      more_samples = join_bare_vertices(out.cover.chosen, out.cover.delta, out);
    log_.detail("joint selection, round " + std::to_string(out.rounds) + ": " + std::to_string(out.chosen.size()) +
                " spheres selected on " + std::to_string(active_.size()) + " of " +
                std::to_string(frames_.frame_count()) + " frames and " + std::to_string(samples_elsewhere()) +
                " samples of the others; then " + std::to_string(more_samples) + " more samples, " +
                std::to_string(more_frames.size()) + " more frames");
    if (more_samples == 0 && more_frames.empty()) break;
    select_on_whole(more_frames);
    if (touching()) touch_out_of_reach(every_vertex_of(more_frames), opt_.target, false);
  }
  // What decided the size is the last round's: samples of other frames out of reach, or reached
  // only after the first round, change whether the tolerance was met (cover_for's rule). Where
  // vertices out of reach were offered balls through them, the tolerance (on the vertices) waits
  // on those no ball reaches, not on the field.
  out.vertices_out_of_reach += vertices_in(out.cover.uncovered).size();
  if (out.limited_by == Limit::tolerance || out.limited_by == Limit::resolution) {
    const bool bare = touching() ? out.vertices_out_of_reach > 0 : out.out_of_reach() > 0;
    // Across an open mesh's holes every radius is its field's bound, which a finer field raises.
    out.limited_by = !bare ? Limit::tolerance
                     : !touching() || opt_.field_bounds_radii ? Limit::resolution
                     : one_ ? Limit::motion
                            : Limit::reach;
  }
  if (refining()) {
    out.refined_moves = refine(out.chosen, out.cover.delta);
    polish(out);
  }
  out.candidates = candidates_.size();
  out.below_min_radius = below_min_radius_;
  out.largest_below_min = largest_below_min_;
  out.from_frames = from_frames_;
  out.touched = vertices_offered(1);
  out.from_touching = balls_offered_[0];
  out.around = vertices_offered(2);
  out.from_around = balls_offered_[1];
  out.frames = active_;
  out.samples_elsewhere = samples_elsewhere();
  out.spaced_frames = spaced_frames_;
  out.vertex_spacing = spaced_frames_ > 0 ? kCoverSpacing * opt_.target : 0;
  if (spaced_frames_ > 0)
    log_.info("covered on " + std::to_string(spaced_frames_) + " frames' vertices an eighth of the tolerance apart (and " +
              std::to_string(out.spaced_joined) + " a cover left near or past it), then every vertex checked");
  out.clip_shrunk = clip_shrunk_;
  note_unused_budget(out.limited_by, out.chosen.size(), opt_.budget, log_);
  return out;
}

void JointSelector::take_chosen(const CoverProblem& problem, JointSelection& out) const {
  std::vector<int> order = out.cover.chosen;
  // Largest first by the rest sphere each becomes, as sphere-pack orders its spheres.
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    return rest_radius(problem, a) > rest_radius(problem, b);
  });
  out.chosen = pick(candidates_, order);
  if (one_)
    for (size_t n = 0; n < order.size(); ++n) out.chosen[n].radius = radius_[size_t(order[n])];
  out.samples = problem.sample_count();
}

size_t JointSelector::refine(SphereSet& chosen, double delta) {
  for (size_t f = 0; f < frames_.frame_count(); ++f) samples(f);  // over every frame, as drawn here
  return refine_chosen(frames_, samples_, opt_.refine_step, opt_.min_radius, chosen, delta, log_);
}

void JointSelector::polish(JointSelection& out) {
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

std::vector<std::vector<uint32_t>> JointSelector::kept_by_frame(const std::vector<uint32_t>& kept) const {
  std::vector<std::vector<uint32_t>> out(frames_.frame_count());
  for_each_stacked(kept, [&](size_t f, uint32_t i) { out[f].push_back(i); });
  for (auto& list : out) std::sort(list.begin(), list.end());
  return out;
}

size_t JointSelector::vertices_offered(char stage) const {
  size_t n = 0;
  for (const std::vector<char>& frame : touched_)
    n += size_t(std::count_if(frame.begin(), frame.end(), [&](char t) { return t >= stage; }));
  return n;
}

std::vector<uint32_t> JointSelector::vertices_in(const std::vector<uint32_t>& stacked) const {
  std::vector<uint32_t> out;
  size_t n = 0;
  for_each_stacked(stacked, [&](size_t f, uint32_t i) {
    if (i < vertex_count(f)) out.push_back(stacked[n]);
    ++n;
  });
  return out;
}

size_t JointSelector::samples_elsewhere() const {
  size_t n = 0;
  for (size_t f = 0; f < extra_.size(); ++f) n += is_active(f) ? 0 : extra_[f].size();
  return n;
}

std::vector<uint32_t> JointSelector::every_sample(size_t f) {
  std::vector<uint32_t> out(samples(f).size());
  std::iota(out.begin(), out.end(), 0u);
  return out;
}

const std::vector<uint32_t>& JointSelector::working(size_t f) {
  if (working_[f].empty()) {
    const bool spacing = opt_.spaced_vertices && opt_.budget == 0 && opt_.target > 0;
    double spaced_by = 0;
    working_[f] = samples_to_cover(samples(f), vertex_count(f), spacing ? kCoverSpacing * opt_.target : 0, spaced_by);
    spaced_frames_ += spaced_by > 0;
  }
  return working_[f];
}

size_t JointSelector::working_vertices(size_t f) {
  const std::vector<uint32_t>& w = working(f);
  return size_t(std::lower_bound(w.begin(), w.end(), uint32_t(vertex_count(f))) - w.begin());
}

size_t JointSelector::join_bare_vertices(const std::vector<int>& chosen, double delta, JointSelection& out) {
  std::vector<std::pair<size_t, std::vector<uint32_t>>> joining;
  for (size_t f : active_) {
    const size_t vertices = vertex_count(f);
    if (working_vertices(f) == vertices) continue;  // not spaced, or every vertex joined
    std::vector<char> in(vertices, 0);
    for (uint32_t i : working(f))
      if (i < vertices) in[i] = 1;
    SphereSet spheres;
    for (int c : chosen) spheres.push_back(sphere(size_t(c), f));
    std::vector<uint32_t> bare;
    const std::vector<Eigen::Vector3d> points(samples_[f].begin(), samples_[f].begin() + long(vertices));
    for (uint32_t i : bare_samples(points, spheres, kNearlyBareSpaced * delta))
      if (!in[i]) bare.push_back(i);
    if (!bare.empty()) joining.emplace_back(f, std::move(bare));
  }
  if (joining.empty()) return 0;
  offer_frame_candidates(joining);
  if (touching()) touch_out_of_reach(joining, opt_.target, false);
  size_t joined = 0;
  for (const auto& [f, bare] : joining) {
    std::vector<uint32_t>& w = working_[f];
    w.insert(w.end(), bare.begin(), bare.end());
    std::sort(w.begin(), w.end());
    joined += bare.size();
  }
  out.spaced_joined += joined;
  return joined;
}

void JointSelector::cover_round(const CoverProblem& problem, bool warm, JointSelection& out) {
  // A round's cover takes seconds on a long clip: the round under way, on a terminal.
  log_.begin("joint selection, round " + std::to_string(out.rounds) + " (" + std::to_string(problem.sample_count()) +
             " samples)");
  if (warm)
    warm_cover(problem, out.cover);
  else
    out.cover = cover_for(problem, opt_.target, opt_.budget, out.limited_by, log_,
                          refining() ? kRefinedBudgetSlack : kBudgetSlack);
}

void JointSelector::warm_cover(const CoverProblem& problem, CoverResult& cover) {
  // Skinned, a round's samples are mostly the last one's, and its candidates only grow: their
  // pairs are kept (a radius the check lowers clears them; one radius for every frame, so a
  // candidate is never withdrawn in some rounds and not others).
  if (one_ && !(cache_ && cache_->delta() == cover.delta)) cache_ = std::make_unique<CoverageCache>(cover.delta);
  const Coverage coverage =
      one_ ? cache_->coverage(problem.samples, candidates_.size(),
                              [&](size_t part, size_t c) { return sphere(c, layout_[part].first); }, layout_)
           : coverage_at(problem, cover.delta);
  cover.chosen = smallest_cover(coverage, kWarmSearch, 0, nullptr, log_, cover.chosen, &cover.kept_samples);
  cover.uncovered = uncovered_samples(coverage);
}

JointSelector::Checked JointSelector::check_radii(const std::vector<size_t>& candidates) {
  std::vector<size_t> unchecked;
  for (size_t c : candidates)
    if (!checked_[c]) unchecked.push_back(c);
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
    radius_[unchecked[n]] = at_least_min_radius(least[n]);
  }
  if (lowered > 0 && cache_) cache_->clear();
  return {unchecked.size(), lowered};
}

bool JointSelector::lower_unchecked_radii(const std::vector<int>& chosen, JointSelection& out) {
  const Checked c = check_radii(std::vector<size_t>(chosen.begin(), chosen.end()));
  out.radii_checked += c.checked;
  out.radii_lowered += c.lowered;
  return c.lowered > 0;
}

bool JointSelector::chosen_radius_lowered(JointSelection& out, size_t& in_a_row) {
  if (!lower_unchecked_radii(out.cover.chosen, out)) {
    in_a_row = 0;
    return false;
  }
  ++out.covers_redone;
  if (++in_a_row == 2) check_every_radius(out);
  return true;
}

void JointSelector::check_every_radius(JointSelection& out) {
  std::vector<size_t> every(candidates_.size());
  std::iota(every.begin(), every.end(), size_t(0));
  const Checked c = check_radii(every);
  out.candidates_checked += c.checked;
  out.candidates_lowered += c.lowered;
  log_.detail("joint selection: the check lowered radii twice in a row; every candidate checked (" +
              std::to_string(c.lowered) + " lowered)");
}

double JointSelector::rest_radius(const CoverProblem& problem, int c) const {
  return one_ ? radius_[size_t(c)] : problem.spheres[0][size_t(c)].radius;
}

CoverProblem JointSelector::cover_problem(size_t& mostly_absent, bool spheres) {
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
    for (size_t f : active_) add(f, working(f), working_vertices(f));
  for (size_t f = 0; f < extra_.size(); ++f)
    if (!extra_[f].empty()) add(f, extra_[f], 0);
  mostly_absent = spheres ? withdraw_mostly_absent(p) : 0;
  return p;
}

size_t JointSelector::add_bare_samples(const std::vector<int>& chosen, double delta, JointSelection& out,
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
  const std::vector<std::vector<uint32_t>> out_of_reach = touch_out_of_reach(bare, delta, true);
  std::vector<std::vector<uint32_t>> joining(frames);
  size_t added = 0;
  out.bare_elsewhere = out.vertices_out_of_reach = 0;
  for (size_t b = 0; b < bare.size(); ++b) {
    const auto& [f, which] = bare[b];
    const std::vector<uint32_t>& out_of_reach_here = out_of_reach[b];
    out.bare_elsewhere += out_of_reach_here.size();
    for (uint32_t o : out_of_reach_here)
      out.vertices_out_of_reach += which[o] < vertex_count(f);
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

std::vector<size_t> JointSelector::frames_left_bare(const std::vector<int>& chosen, double delta) {
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

std::string out_of_reach_wording(const JointSelection& selection, const JointSelectionOptions& options, bool skinned) {
  const size_t count = selection.out_of_reach();
  const size_t vertices = selection.vertices_out_of_reach;
  const std::string head = std::to_string(count) + " surface samples over the poses are farther than " +
                           num(selection.cover.delta) + " from every candidate sphere mapped there";
  if (!(options.target > 0))
    return head + (skinned ? " (a skinned sphere keeps one radius, the least over the frames: where parts move against "
                             "each other no candidate keeps one large enough, whatever the resolution; thin parts at "
                             "the field's resolution also need a finer sdf-build resolution)"
                           : " (thin parts at the field's resolution; a finer sdf-build resolution gives candidates "
                             "closer to them)");
  const std::string between = std::to_string(count - vertices) + " of them between the vertices, where the tolerance "
                              "is not asked and no ball of their own is offered";
  if (vertices == 0) return head + ": " + between;
  const size_t bare = selection.vertices_with_no_solid;
  const std::string no_solid = "no solid beside them in their pose (" + std::string(kNoSolidBeside) + ")";
  const std::string bound = "no ball through them reaches within the field's bound across the holes (a finer "
                            "sdf-build resolution raises it)";
  const std::string why =
      options.field_bounds_radii
          ? (bare == 0           ? "which " + bound
             : bare >= vertices ? "which have " + no_solid + ", and no sphere touches them at any resolution"
                                : std::to_string(bare) + " of them with " + no_solid +
                                      ", which no sphere touches at any resolution; the others " + bound)
      : skinned ? "which no ball through them or around them keeps reaching in every frame (a skinned sphere keeps "
                  "one radius, the least over the frames, and where the skin folds none does), whatever the resolution"
                : "which no inscribed ball through them reaches (sharp features)";
  const std::string small = selection.below_min_radius > 0
                                ? " (or no candidate of at least the least radius " + num(options.min_radius) +
                                      ", --min-radius: " + std::to_string(selection.below_min_radius) +
                                      " smaller ones withdrawn)"
                                : "";
  const std::string near = selection.out_of_reach_added > 0
                               ? " (" + std::to_string(selection.out_of_reach_added) +
                                     " of the spheres bring them as near as any candidate comes)"
                               : "";
  return head + ": " + std::to_string(vertices) + " of them vertices, " + why + small + near + "; " + between;
}

JointSelection select_jointly(SelectionFrames& frames, const SphereSet& candidates, const JointSelectionOptions& options,
                              Log& log) {
  return JointSelector(frames, options, log).run(candidates);
}

}  // namespace spx
