#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "pack/cover.hpp"
#include "pack/sample_grid.hpp"

namespace spx {
using detail::SampleGrid;

namespace {

// Gaps between samples (stacked over poses) and candidates, and each sample's two nearest
// chosen spheres among those that cover it at delta.
class CoverState {
 public:
  CoverState(const CoverProblem& problem, const Coverage& cov, double delta)
      : problem_(problem), cov_(cov), delta_(delta) {
    for (size_t k = 0; k < problem.samples.size(); ++k)
      for (size_t i = 0; i < problem.samples[k].size(); ++i) {
        where_.emplace_back(uint32_t(k), uint32_t(i));
        weight_.push_back(problem.weighted.empty() || i < problem.weighted[k] ? 1.0 : 0.0);
      }
    const Coverage covering = covering_candidates(cov);
    by_start_ = covering.start;
    by_ = covering.samples;
    in_.assign(cov.start.size() - 1, 0);
    first_.assign(cov.sample_count, -1);
    second_.assign(cov.sample_count, -1);
  }

  double weight(uint32_t s) const { return weight_[s]; }
  // Infinite for a sphere of radius 0: it is absent from that pose and covers nothing there,
  // however near its center (as in the coverage rows).
  double gap(uint32_t s, int c) const {
    const auto [k, i] = where_[s];
    const Sphere& sphere = problem_.spheres[k][size_t(c)];
    if (!(sphere.radius > 0)) return std::numeric_limits<double>::infinity();
    return (problem_.samples[k][i] - sphere.center).norm() - sphere.radius;
  }
  // The sample's error with the chosen set: its gap to the nearest chosen sphere covering it
  // (delta's worth past delta where none does: such a sample only arises from uncoverable ones).
  double error(uint32_t s) const { return first_[s] < 0 ? 2 * delta_ : gap(s, first_[s]); }
  double error_without(uint32_t s, int c) const {
    const int best = first_[s] == c ? second_[s] : first_[s];
    return best < 0 ? 2 * delta_ : gap(s, best);
  }

  void set(const std::vector<int>& chosen) {
    std::fill(in_.begin(), in_.end(), 0);
    for (int c : chosen) in_[size_t(c)] = 1;
    for (uint32_t s = 0; s < cov_.sample_count; ++s) update(s);
  }
  void swap(int out, int in) {
    in_[size_t(out)] = 0;
    in_[size_t(in)] = 1;
    for (int c : {out, in})
      for (uint32_t n = cov_.start[size_t(c)]; n < cov_.start[size_t(c) + 1]; ++n) update(cov_.samples[n]);
  }
  void add(int c) {
    in_[size_t(c)] = 1;
    for (uint32_t n = cov_.start[size_t(c)]; n < cov_.start[size_t(c) + 1]; ++n) update(cov_.samples[n]);
  }
  bool chosen(int c) const { return in_[size_t(c)] != 0; }
  int first(uint32_t s) const { return first_[s]; }
  int second(uint32_t s) const { return second_[s]; }
  const uint32_t* covering_begin(uint32_t s) const { return by_.data() + by_start_[s]; }
  const uint32_t* covering_end(uint32_t s) const { return by_.data() + by_start_[s + 1]; }

 private:
  void update(uint32_t s) {
    int a = -1, b = -1;
    double ga = 0, gb = 0;
    for (uint32_t n = by_start_[s]; n < by_start_[s + 1]; ++n) {
      const int c = int(by_[n]);
      if (!in_[size_t(c)]) continue;
      const double g = gap(s, c);
      if (a < 0 || g < ga) {
        b = a, gb = ga;
        a = c, ga = g;
      } else if (b < 0 || g < gb) {
        b = c, gb = g;
      }
    }
    first_[s] = a;
    second_[s] = b;
  }

  const CoverProblem& problem_;
  const Coverage& cov_;
  double delta_;
  std::vector<std::pair<uint32_t, uint32_t>> where_;  // sample -> (pose, index)
  std::vector<double> weight_;
  std::vector<uint32_t> by_start_, by_;
  std::vector<char> in_;
  std::vector<int> first_, second_;
};

// Swaps: a sphere for one that covers every sample only it covers, cutting the summed cost of
// the weighted samples' errors most, in rounds while any does; none takes a sample's error past
// `limit`. Returns the swaps made.
template <class Cost>
size_t swap_rounds(CoverState& state, const Coverage& cov, double delta, std::vector<int>& chosen, const Cost& cost,
                   double limit = std::numeric_limits<double>::infinity()) {
  size_t swaps = 0;
  for (int round = 0; round < 4; ++round) {
    size_t this_round = 0;
    for (size_t slot = 0; slot < chosen.size(); ++slot) {
      const int out = chosen[slot];
      // Samples only `out` covers: a replacement must cover them all.
      std::vector<uint32_t> critical;
      for (uint32_t n = cov.start[size_t(out)]; n < cov.start[size_t(out) + 1]; ++n) {
        const uint32_t s = cov.samples[n];
        if (state.first(s) == out && state.second(s) < 0) critical.push_back(s);
      }
      // Candidates: those covering the first critical sample (every sample of `out` if none).
      const uint32_t anchor = critical.empty() ? cov.samples[cov.start[size_t(out)]] : critical.front();
      std::vector<int> options;
      for (const uint32_t* c = state.covering_begin(anchor); c != state.covering_end(anchor); ++c)
        if (!state.chosen(int(*c))) options.push_back(int(*c));
      std::vector<double> change(options.size(), std::numeric_limits<double>::infinity());
      tbb::parallel_for(size_t(0), options.size(), [&](size_t o) {
        const int in = options[o];
        for (uint32_t s : critical)
          if (state.gap(s, in) > delta) return;
        double sum = 0;
        // Samples losing `out` fall back to their second sphere or to `in`.
        for (uint32_t n = cov.start[size_t(out)]; n < cov.start[size_t(out) + 1]; ++n) {
          const uint32_t s = cov.samples[n];
          if (state.first(s) != out) continue;
          const double g = state.gap(s, in);
          const double after = std::min(state.error_without(s, out), g <= delta ? g : std::numeric_limits<double>::infinity());
          if (after > limit) return;
          sum += state.weight(s) * (cost(after) - cost(state.error(s)));
        }
        // Samples `in` brings closer (those whose nearest is `out` are counted above).
        for (uint32_t n = cov.start[size_t(in)]; n < cov.start[size_t(in) + 1]; ++n) {
          const uint32_t s = cov.samples[n];
          if (state.first(s) == out) continue;
          sum += state.weight(s) * (cost(std::min(state.gap(s, in), state.error(s))) - cost(state.error(s)));
        }
        change[o] = sum;
      });
      size_t best = options.size();
      for (size_t o = 0; o < options.size(); ++o)
        if (change[o] < -1e-12 * delta && (best == options.size() || change[o] < change[best])) best = o;
      if (best == options.size()) continue;
      state.swap(out, options[best]);
      chosen[slot] = options[best];
      ++this_round;
    }
    swaps += this_round;
    if (this_round == 0) break;
  }
  return swaps;
}

// The median and largest of these errors (0 and 0 for none).
std::pair<double, double> median_and_max_of(std::vector<double> errors) {
  if (errors.empty()) return {0, 0};
  const double largest = *std::max_element(errors.begin(), errors.end());
  std::nth_element(errors.begin(), errors.begin() + long(errors.size() / 2), errors.end());
  return {errors[errors.size() / 2], largest};
}

// The weighted samples' median and largest error.
std::pair<double, double> median_and_max(const CoverState& state, size_t samples) {
  std::vector<double> errors;
  for (uint32_t s = 0; s < samples; ++s)
    if (state.weight(s) > 0) errors.push_back(state.error(s));
  return median_and_max_of(std::move(errors));
}

// Passes for the median, by swaps or by moves alike: each pass(cost) lowers a cost counting the
// errors above the median it starts from (the summed error breaks ties) and returns the changes
// made; again from the new median (median_now()) while it falls, at most `passes` times.
// Returns the changes made.
template <class Pass, class Median>
size_t descend_median(double median, double delta, int passes, const Pass& pass, const Median& median_now) {
  const double tie = 1e-7 / delta;  // errors are at most 2 delta: under one sample for 5 million of them
  size_t changes = 0;
  for (int n = 0; n < passes; ++n) {
    const double tau = median;
    const size_t made = pass([&](double e) { return (e > tau ? 1.0 : 0.0) + tie * e; });
    changes += made;
    const double now = median_now();
    if (made == 0 || !(now < median)) break;
    median = now;
  }
  return changes;
}

// Median descent: swaps that bring more weighted samples within the median error than they
// take out of it (the summed error breaks ties), then again from the new median while it falls.
// The sum the swaps before it lowered is a poor proxy for the median: a swap that lowers many
// errors a little below the median and raises a few far above it counts as a loss there. No
// weighted sample's error rises past the largest one's before. Returns the swaps made.
size_t median_descent(CoverState& state, const Coverage& cov, double delta, std::vector<int>& chosen) {
  const auto [median, largest] = median_and_max(state, cov.sample_count);
  return descend_median(
      median, delta, 20,
      [&](const auto& cost) { return swap_rounds(state, cov, delta, chosen, cost, largest); },
      [&] { return median_and_max(state, cov.sample_count).first; });
}

}  // namespace

void improve_cover(const CoverProblem& problem, const Coverage& cov, double delta, size_t max_spheres,
                   std::vector<int>& chosen, Log& log, bool lower_median) {
  if (chosen.empty()) return;
  CoverState state(problem, cov, delta);
  state.set(chosen);
  const size_t candidates = cov.start.size() - 1;
  // Spare budget: the candidate that cuts the total error most, while one does.
  size_t added = 0;
  while (chosen.size() < max_spheres) {
    std::vector<double> cut(candidates, 0);
    tbb::parallel_for(size_t(0), candidates, [&](size_t c) {
      if (state.chosen(int(c))) return;
      double sum = 0;
      for (uint32_t n = cov.start[c]; n < cov.start[c + 1]; ++n)
        sum += state.weight(cov.samples[n]) * std::max(0.0, state.error(cov.samples[n]) - state.gap(cov.samples[n], int(c)));
      cut[c] = sum;
    });
    const size_t best = size_t(std::max_element(cut.begin(), cut.end()) - cut.begin());
    if (!(cut[best] > 0)) break;
    state.add(int(best));
    chosen.push_back(int(best));
    ++added;
  }
  size_t swaps = swap_rounds(state, cov, delta, chosen, [](double e) { return e; });
  const size_t median_swaps = lower_median ? median_descent(state, cov, delta, chosen) : 0;
  log.detail("cover improved: " + std::to_string(added) + " spheres added, " + std::to_string(swaps) + " swaps" +
             (lower_median ? ", " + std::to_string(median_swaps) + " for the median" : ""));
}

namespace {

// The refinement's state over one pose or several: each sample's nearest and second-nearest
// sphere in its own pose, and moves of one sphere's rest centre along `directions` (the first of
// direction()'s) that cut a cost summed over the weighted samples' errors. A sphere is its rest
// centre and what spheres_at makes of it in every pose; samples are stacked pose after pose.
class OffGrid {
 public:
  OffGrid(const std::vector<std::vector<Eigen::Vector3d>>& samples, const std::vector<size_t>& weighted,
          std::vector<Eigen::Vector3d>& centers, std::vector<SphereSet>& spheres, const PoseSpheresAt& spheres_at,
          double delta, int directions)
      : directions_(directions), centers_(centers), spheres_(spheres), spheres_at_(spheres_at), delta_(delta) {
    for (size_t p = 0; p < samples.size(); ++p) {
      first_of_.push_back(uint32_t(points_.size()));
      grids_.emplace_back(samples[p], false);  // fixed cells: the moves' sums count every sample visited
      for (size_t i = 0; i < samples[p].size(); ++i) {
        points_.push_back(samples[p][i]);
        pose_.push_back(uint32_t(p));
        weighted_.push_back(i < weighted[p]);
      }
    }
    first_.assign(points_.size(), -1);
    second_.assign(points_.size(), -1);
    tbb::parallel_for(size_t(0), points_.size(), [&](size_t i) { rank(i); });
  }

  // The weighted samples' median and largest error.
  std::pair<double, double> median_and_max() const {
    std::vector<double> e;
    for (size_t i = 0; i < points_.size(); ++i)
      if (weighted_[i]) e.push_back(gap(i, sphere(size_t(first_[i]), i)));
    return median_and_max_of(std::move(e));
  }

  // Rounds of moves by `step` (then halved down to `last`), each the one of the directions that
  // cuts the summed cost most; no sample's error rises past `ceiling` (weighted) or delta (the others).
  template <class Cost>
  size_t move_rounds(double step, double last, double ceiling, const Cost& cost) {
    size_t moves = 0;
    const size_t n = centers_.size();
    for (double s = step; s >= last; s /= 2) {
      // A sphere that found no move is not asked again until one near it (in some pose) moves:
      // the samples its moves would count are those within its radius, delta and two steps.
      std::vector<char> settled(n, 0);
      for (int round = 0; round < 3; ++round) {
        size_t this_round = 0;
        for (size_t j = 0; j < n; ++j) {
          if (settled[j]) continue;
          std::vector<Sphere> old(spheres_.size());
          for (size_t p = 0; p < old.size(); ++p) old[p] = spheres_[p][j];
          if (!move_one(j, s, ceiling, cost)) {
            settled[j] = 1;
            continue;
          }
          ++this_round;
          for (size_t k = 0; k < n; ++k)
            for (size_t p = 0; p < old.size() && settled[k]; ++p) {
              const Sphere &a = spheres_[p][k], &b = spheres_[p][j];
              const double reach = a.radius + 2 * delta_ + 2 * s;
              if ((a.center - old[p].center).norm() <= reach + old[p].radius ||
                  (a.center - b.center).norm() <= reach + b.radius)
                settled[k] = 0;
            }
        }
        moves += this_round;
        if (this_round == 0) break;
      }
    }
    return moves;
  }

 private:
  const Sphere& sphere(size_t j, size_t i) const { return spheres_[pose_[i]][j]; }
  double gap(size_t i, const Sphere& s) const { return (points_[i] - s.center).norm() - s.radius; }
  void rank(size_t i) {
    int a = -1, b = -1;
    double ga = 0, gb = 0;
    for (size_t j = 0; j < centers_.size(); ++j) {
      const double g = gap(i, sphere(j, i));
      if (a < 0 || g < ga) {
        b = a, gb = ga;
        a = int(j), ga = g;
      } else if (b < 0 || g < gb) {
        b = int(j), gb = g;
      }
    }
    first_[i] = a;
    second_[i] = b;
  }
  double error_without(size_t i, size_t j) const {
    const int k = first_[i] == int(j) ? second_[i] : first_[i];
    return k < 0 ? std::numeric_limits<double>::infinity() : gap(i, sphere(size_t(k), i));
  }
  // The samples whose error can change with a sphere that is `s` in each pose (near it), as
  // bits, added to `marked`.
  void mark_near(const std::vector<Sphere>& s, std::vector<uint64_t>& marked) const {
    marked.resize(points_.size() / 64 + 1, 0);
    for (size_t p = 0; p < s.size(); ++p)
      grids_[p].near(s[p].center, s[p].radius + delta_, [&](uint32_t i) {
        const uint32_t n = first_of_[p] + i;
        marked[n >> 6] |= uint64_t(1) << (n & 63);
      });
  }
  // Those near a sphere whose samples are marked in `around` or near `b`, ascending: read back
  // from the bits in order (a sort of thousands of indices per direction was a tenth of a
  // joint refinement's time).
  std::vector<uint32_t> near_either(const std::vector<uint64_t>& around, const std::vector<Sphere>& b) const {
    std::vector<uint64_t> marked(around);
    mark_near(b, marked);
    std::vector<uint32_t> out;
    for (size_t w = 0; w < marked.size(); ++w)
      for (uint64_t bits = marked[w]; bits; bits &= bits - 1) out.push_back(uint32_t(w * 64 + size_t(__builtin_ctzll(bits))));
    return out;
  }

  template <class Cost>
  bool move_one(size_t j, double s, double ceiling, const Cost& cost) {
    std::vector<Sphere> old(spheres_.size());
    for (size_t p = 0; p < old.size(); ++p) old[p] = spheres_[p][j];
    std::vector<uint64_t> around;  // the same for every direction
    mark_near(old, around);
    std::vector<std::vector<Sphere>> moved(static_cast<size_t>(directions_));
    std::vector<double> change(size_t(directions_), std::numeric_limits<double>::infinity());
    // The directions side by side: each sum is its own, the best taken in order below.
    tbb::parallel_for(0, directions_, [&](int d) {
      const Eigen::Vector3d c = centers_[j] + s * direction(d);
      std::vector<Sphere>& m = moved[size_t(d)];
      if (!spheres_at_(c, m)) return;
      double sum = 0;
      for (uint32_t i : near_either(around, m)) {
        const double before = gap(i, sphere(size_t(first_[i]), i));
        const double after = std::min(error_without(i, j), gap(i, m[pose_[i]]));
        if (after > (weighted_[i] ? ceiling : delta_) && after > before) return;
        if (weighted_[i]) sum += cost(after) - cost(before);
      }
      change[size_t(d)] = sum;
    });
    int best = -1;
    double best_change = -1e-12 * cost(delta_);
    for (int d = 0; d < directions_; ++d)
      if (change[size_t(d)] < best_change) {
        best_change = change[size_t(d)];
        best = d;
      }
    if (best < 0) return false;
    centers_[j] += s * direction(best);
    for (size_t p = 0; p < spheres_.size(); ++p) spheres_[p][j] = moved[size_t(best)][p];
    for (uint32_t i : near_either(around, moved[size_t(best)])) rank(i);
    return true;
  }

  // Along the axes (0-5), then the cube's diagonals (6-13), each of unit length.
  static Eigen::Vector3d direction(int d) {
    Eigen::Vector3d out = Eigen::Vector3d::Zero();
    if (d < 6) {
      out[d / 2] = d % 2 ? 1 : -1;
      return out;
    }
    const int b = d - 6;
    return Eigen::Vector3d(b & 1 ? 1 : -1, b & 2 ? 1 : -1, b & 4 ? 1 : -1) / std::sqrt(3.0);
  }

  int directions_;
  std::vector<Eigen::Vector3d> points_;  // every pose's samples, stacked
  std::vector<uint32_t> pose_;           // per sample: its pose
  std::vector<char> weighted_;           // per sample: a vertex, whose error counts
  std::vector<uint32_t> first_of_;       // per pose: its first sample
  std::vector<SampleGrid> grids_;        // per pose
  std::vector<Eigen::Vector3d>& centers_;
  std::vector<SphereSet>& spheres_;  // per pose, per sphere
  const PoseSpheresAt& spheres_at_;
  double delta_;
  std::vector<int> first_, second_;
};

}  // namespace

// Budget mode's refinement: the max first. Its moves cut the weighted errors summed to this
// power (relative to the largest), which the largest few dominate: a move that lowers the worst
// sample's error and raises its neighbours' a little is taken where the total would refuse it.
constexpr double kMaxPower = 128;
// Directions a centre moves along: the axes, and in budget mode the cube's diagonals too (a
// sphere between two others is often stuck along the axes alone).
constexpr int kAxes = 6, kAxesAndDiagonals = 14;
// The median's passes (each from the median the last one left): the first few make most of its
// gain (frontier-bench, the bunny at 256: 20 passes took 19 s for a median 0.005 % of the
// diagonal lower than 6 did in 7.5 s).
constexpr int kMedianPasses = 6;

size_t refine_jointly(const std::vector<std::vector<Eigen::Vector3d>>& samples, const std::vector<size_t>& weighted,
                      std::vector<Eigen::Vector3d>& centers, std::vector<SphereSet>& spheres,
                      const PoseSpheresAt& spheres_at, double delta, double step, Log& log, bool keep_max) {
  if (centers.empty() || samples.empty()) return 0;
  OffGrid state(samples, weighted, centers, spheres, spheres_at, delta, keep_max ? kAxesAndDiagonals : kAxes);
  if (!keep_max) {
    // Tolerance mode: the total, no sample leaving delta.
    const size_t moves = state.move_rounds(step, step / 4, delta, [](double e) { return e; });
    log.detail("refined centers: " + std::to_string(moves) + " moves");
    return moves;
  }
  // The max, down to an eighth of the step.
  const double top = std::max(state.median_and_max().second, 1e-300);
  const size_t for_max = state.move_rounds(
      step, step / 8, top, [&](double e) { return std::pow(std::max(e, 0.0) / top, kMaxPower); });
  // Then the total and the median (as median_descent does with the candidates), neither raising
  // a weighted sample's error past the largest now.
  const double ceiling = state.median_and_max().second;
  const size_t for_total = state.move_rounds(step, step / 4, ceiling, [](double e) { return e; });
  const size_t for_median = descend_median(
      state.median_and_max().first, delta, kMedianPasses,
      [&](const auto& cost) { return state.move_rounds(step, step / 8, ceiling, cost); },
      [&] { return state.median_and_max().first; });
  log.detail("refined centers: " + std::to_string(for_max) + " moves for the max, " + std::to_string(for_total) +
             " for the total, " + std::to_string(for_median) + " for the median");
  return for_max + for_total + for_median;
}

size_t refine_off_grid(const std::vector<Eigen::Vector3d>& samples, size_t weighted, SphereSet& spheres,
                       const std::function<double(const Eigen::Vector3d&)>& radius_at, double delta, double step,
                       Log& log, bool keep_max) {
  // One pose, the rest: a sphere is its centre and the radius there.
  std::vector<Eigen::Vector3d> centers;
  for (const Sphere& s : spheres) centers.push_back(s.center);
  std::vector<SphereSet> one{spheres};
  const PoseSpheresAt at = [&](const Eigen::Vector3d& c, std::vector<Sphere>& out) {
    const double r = radius_at(c);
    if (!(r > 0)) return false;
    out.assign(1, Sphere{c, r});
    return true;
  };
  const size_t moves = refine_jointly({samples}, {weighted}, centers, one, at, delta, step, log, keep_max);
  spheres = std::move(one[0]);
  return moves;
}

}  // namespace spx
