#pragma once
// Inside pose-map's joint selection (joint_selection.hpp says what it does): the selector's state
// as it grows, and its steps. joint_selection.cpp runs the rounds (covers, checks, the polish);
// selection_offers.cpp offers candidates (the spheres file's, each frame's own, and balls through
// the vertices nothing else reaches) and tells which samples they reach.
#include <Eigen/Core>
#include <algorithm>
#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

#include "core/pick.hpp"
#include "pack/coverage.hpp"
#include "posemap/joint_selection.hpp"

namespace spx {

// The selection's state as it grows: the candidates (rest), the frames selected on whole, each
// candidate's sphere there (not skinned) or its centre in every frame and its one radius
// (skinned), and the samples of other frames added (skinned).
class JointSelector {
 public:
  JointSelector(SelectionFrames& frames, const JointSelectionOptions& opt, Log& log)
      : frames_(frames),
        opt_(opt),
        log_(log),
        one_(frames.one_radius()),
        own_(frames.frame_count()),
        samples_(frames.frame_count()),
        triangles_(frames.frame_count()),
        touched_(frames.frame_count()),
        offered_(frames.frame_count()),
        extra_(frames.frame_count()),
        held_(frames.frame_count()),
        working_(frames.frame_count()),
        centers_(one_ ? frames.frame_count() : 0) {}

  JointSelection run(const SphereSet& file_candidates);

 private:
  bool is_active(size_t f) const { return std::binary_search(active_.begin(), active_.end(), f); }
  // Frame f's vertices: the first of its samples, and where the error (and the tolerance) is measured.
  size_t vertex_count(size_t f) const { return frames_.frame_surface(f).vertices.size(); }

  // Budget mode: the chosen centres are refined off the candidates (below).
  bool refining() const { return opt_.budget > 0 && opt_.refine_step > 0; }
  size_t refine(SphereSet& chosen, double delta);

  // Budget mode, opt_.polish_rounds times: the last refined set joins the candidates, the budget
  // is covered again from the delta where that set is a cover (the problem's largest gap to it),
  // and the cover is refined over every frame; the best set by kept_over on every frame's
  // samples (the worst frame's max, the frames' mean median) is kept, its cover with it. After
  // the refinement, which drew every frame's samples.
  void polish(JointSelection& out);

  // Skinned: the share of delta past which a check adds a sample. Budget mode adds only the bare:
  // its delta is the least the budget reaches, so most samples are covered by more than half of
  // it, the nearly bare would be nearly every sample of the clip, and each round's budget cover
  // (tables of every pair within delta) grows with them (48 frames of the elephant's walk at 64
  // spheres took over 20 GB).
  double nearly_bare() const;

  // Skinned, tolerance: after each round the problem keeps only the samples its reduction kept
  // (a cover of those covers the rest), so that a round costs what the hard samples of the clip
  // cost, not what all its frames do. The candidates stay (each frame's were offered up front).
  bool compacting() const { return one_ && opt_.budget == 0; }

  // Each of the last problem's samples `stacked` (ascending) as fn(frame, index in its samples).
  template <class Fn>
  void for_each_stacked(const std::vector<uint32_t>& stacked, const Fn& fn) const {
    size_t part = 0, first = 0;
    for (uint32_t s : stacked) {
      while (s >= first + layout_[part].second.size()) first += layout_[part++].second.size();
      fn(layout_[part].first, layout_[part].second[s - first]);
    }
  }
  // The reduction's kept samples (stacked indices of the last problem) by frame.
  std::vector<std::vector<uint32_t>> kept_by_frame(const std::vector<uint32_t>& kept) const;
  // Vertices (over every frame) offered balls through them (stage 1) or, skinned, also around
  // them (stage 2).
  size_t vertices_offered(char stage) const;
  // Of the last problem's samples `stacked`, the vertices (where the error is measured).
  std::vector<uint32_t> vertices_in(const std::vector<uint32_t>& stacked) const;

  size_t samples_elsewhere() const;

  const std::vector<Eigen::Vector3d>& samples(size_t f);

  std::vector<uint32_t> every_sample(size_t f);
  // A frame selected on whole: its samples in the problem. Every one, or where its vertices lie
  // much closer together than the tolerance (opt_.spaced_vertices), the vertices kCoverSpacing x
  // it apart and every area sample, joined by the vertices a cover leaves past it
  // (join_bare_vertices). Ascending, the vertices first.
  const std::vector<uint32_t>& working(size_t f);
  // Of working(f), the vertices.
  size_t working_vertices(size_t f);
  // Each frame's working vertices (its samples drawn here, before out_of_reach_of reads them side
  // by side).
  std::vector<std::pair<size_t, std::vector<uint32_t>>> every_vertex_of(const std::vector<size_t>& frames);
  // Spaced frames: the vertices left out of working(f) that `chosen` leaves past (nearly) `delta` join it,
  // their frame's candidates and balls through them offered as to any frame's. Returns how many.
  size_t join_bare_vertices(const std::vector<int>& chosen, double delta, JointSelection& out);

  // Tolerance mode: samples out of reach of every candidate are offered balls touching them.
  bool touching() const { return opt_.target > 0; }
  // Of each frame's samples `which`, the positions of those no candidate reaches within delta,
  // after (touching) the vertices not offered it before are offered balls touching them in their
  // frame: a sample far from every medial voxel, or one whose candidates a skinned clip shrinks,
  // is still reached by a ball through it. Skinned, those still out of reach are then offered
  // balls around them (a fold of the skin cuts every ball through a vertex in some frame, and a
  // small ball beside it may stay inside in all). `cached`: as out_of_reach_of.
  std::vector<std::vector<uint32_t>> touch_out_of_reach(
      const std::vector<std::pair<size_t, std::vector<uint32_t>>>& wanting, double delta, bool cached);

  // Not skinned: `count` new candidates marked where their rest sphere (`at_rest`, asked only
  // where min_radius is) is smaller than min_radius; withdraw_small then sets those among a
  // frame's spheres of the candidates from `first` on to 0 (covering nothing, as a candidate
  // mostly absent).
  void mark_small(const SphereSet& at_rest, size_t count);
  // Skinned: a candidate's one radius, or 0 where it is smaller than min_radius (counted).
  double at_least_min_radius(double r) {
    if (!(r > 0 && r < opt_.min_radius)) return r;
    note_below_min(r);
    return 0;
  }
  void note_below_min(double r) {
    ++below_min_radius_;
    largest_below_min_ = std::max(largest_below_min_, r);
  }
  void withdraw_small(SphereSet& in_frame, size_t first) const;

  // Candidate c in frame f as the problem has it.
  Sphere sphere(size_t c, size_t f) const { return one_ ? Sphere{centers_[f][c], radius_[c]} : own_[f][c]; }

  // The cover's spheres as the proxy's rest spheres (out.chosen), largest first.
  void take_chosen(const CoverProblem& problem, JointSelection& out) const;

  // The round's cover, in full or (`warm`) from the last round's.
  void cover_round(const CoverProblem& problem, bool warm, JointSelection& out);
  // Tolerance mode, after the first round: the last cover completed for what was added, then
  // searched briefly, so that it stays near the last one and the next check finds little new.
  void warm_cover(const CoverProblem& problem, CoverResult& cover);

  // Skinned: each chosen candidate's one radius, not checked before, checked against its exact
  // radius in every frame (the carry skips frames by their fields' floors, which may be a
  // fraction of a voxel high). Returns whether any was lowered.
  bool lower_unchecked_radii(const std::vector<int>& chosen, JointSelection& out);
  // The round's chosen radii checked (lower_unchecked_radii): whether one was lowered, so that
  // the same problem is covered again. `in_a_row` counts the lowerings since a cover held; at two,
  // every candidate is checked (check_every_radius).
  bool chosen_radius_lowered(JointSelection& out, size_t& in_a_row);
  // Of `candidates`, those not checked before checked so: how many, and how many it lowered.
  struct Checked {
    size_t checked = 0, lowered = 0;
  };
  Checked check_radii(const std::vector<size_t>& candidates);
  // Every candidate not checked before checked so: once a round's check has lowered radii twice in
  // a row, the cover is trading each lowered sphere for another the floors overrate (a dense
  // frame's, or a clip's where they run high), and each re-cover of a large problem takes seconds.
  void check_every_radius(JointSelection& out);

  // More candidates: their spheres in the frames selected on or, skinned, their centres in every
  // frame and their one radius.
  void add_candidates(const SphereSet& more);

  // Frames `more` are selected on whole: every candidate mapped there (not skinned), and their
  // samples no candidate of the spheres file comes within reach of are offered their own
  // candidates.
  void select_on_whole(const std::vector<size_t>& more);

  // Skinned: every frame's samples far from the spheres file's candidates are offered that
  // frame's own (what the one cover over every frame would be offered).
  void offer_every_frame();

  // Of each frame's samples `which`, those no candidate of the spheres file comes within reach
  // of (and not offered before) are offered that frame's own candidates near them: every
  // frame's far samples found first, then the pool grows frame by frame. `progress`: the stage's
  // name for a percentage on a terminal (a whole clip's frames take a while).
  void offer_frame_candidates(const std::vector<std::pair<size_t, std::vector<uint32_t>>>& wanting,
                              const char* progress = nullptr);

  // Candidate c's radius in the rest (skinned: its one radius; a problem of samples alone has no
  // spheres).
  double rest_radius(const CoverProblem& problem, int c) const;

  // The frames selected on, whole, then (skinned) the samples added from the others, as one
  // cover problem. Candidates mostly absent are withdrawn (counted). Without `spheres`, the
  // samples alone (a skinned candidate is absent in every frame or in none: none is withdrawn).
  CoverProblem cover_problem(size_t& mostly_absent, bool spheres);

  // Skinned: the samples the chosen spheres leave bare, or cover by less than kNearlyBare of
  // delta, that the problem does not hold (one it held before only if bare outright). Those far
  // from the spheres file's candidates are offered their frame's own first; then those some
  // candidate reaches join the problem, the rest are counted in `out.bare_elsewhere` (the vertices
  // among them in `out.vertices_out_of_reach`). `kept` (compacting): the samples the last
  // problem's reduction kept; the problem becomes those and the samples joining. Returns how
  // many joined.
  size_t add_bare_samples(const std::vector<int>& chosen, double delta, JointSelection& out,
                          const std::vector<uint32_t>* kept);

  // Of each frame's samples `which`, the positions of those no candidate reaches. Compacting and
  // `cached`, the cache finds them: the columns it computes are those the next round's problem asks for.
  std::vector<std::vector<uint32_t>> out_of_reach_of(const std::vector<std::pair<size_t, std::vector<uint32_t>>>& bare,
                                                     double delta, bool cached);

  // Not skinned: the frames not selected on where the chosen spheres (grown there) leave
  // samples bare, the most first, at most frames_per_round.
  std::vector<size_t> frames_left_bare(const std::vector<int>& chosen, double delta);

  SelectionFrames& frames_;
  const JointSelectionOptions& opt_;
  Log& log_;
  const bool one_;                                     // skinned: one radius per sphere
  SphereSet candidates_;                               // rest pose
  std::vector<size_t> active_;                         // frames selected on whole, ascending
  std::vector<SphereSet> own_;                         // not skinned, per frame selected on: each candidate's sphere
  std::vector<std::vector<Eigen::Vector3d>> samples_;  // per frame, drawn when first asked
  std::vector<std::vector<int>> triangles_;            // per frame: each area sample's triangle (sample_surface)
  std::vector<std::vector<char>> touched_;             // per frame and sample: balls through it offered (1), around (2)
  std::vector<std::vector<char>> offered_;             // per frame and sample: its frame's candidates offered
  std::vector<std::vector<uint32_t>> extra_;           // skinned, per frame not whole: its samples in the problem
  std::vector<std::vector<char>> held_;                // per frame and sample: it has been in the problem
  std::vector<std::vector<uint32_t>> working_;         // per frame selected on: working(f), once asked
  bool whole_ = true;                                  // the frames selected on are whole in the problem
  std::vector<std::pair<size_t, std::vector<uint32_t>>> layout_;  // the last problem's samples: (frame, which)
  std::vector<std::vector<Eigen::Vector3d>> centers_;  // skinned, per frame: each candidate's centre there
  std::vector<double> radius_;                         // skinned: each candidate's one radius
  std::vector<char> small_;                            // not skinned: smaller at rest than min_radius (withdrawn)
  std::vector<char> checked_;                          // skinned: its radius checked in every frame
  std::unique_ptr<CoverageCache> cache_;              // skinned, tolerance: the pairs kept from round to round
  size_t from_frames_ = 0;
  size_t spaced_frames_ = 0;  // frames whose working samples are spaced vertices
  size_t balls_offered_[2] = {0, 0};  // tolerance: balls through vertices out of reach, and (skinned) around them
  size_t clip_shrunk_ = 0;  // skinned: candidates whose radius the clip lowered
  size_t below_min_radius_ = 0;  // candidates withdrawn, smaller at rest than min_radius,
  double largest_below_min_ = 0; // the largest of them
  size_t file_count_ = 0;  // the candidates [0, file_count_) are the spheres file's
};

}  // namespace spx
