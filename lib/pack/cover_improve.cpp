#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>

#include "pack/cover.hpp"
#include "pack/median_descent.hpp"
#include "pack/sample_grid.hpp"

namespace spx {
using detail::descend_median;
using detail::median_and_max_of;
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
    error_.assign(cov.sample_count, 2 * delta);
    second_error_.assign(cov.sample_count, 2 * delta);
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
  // Kept as the nearest two are found: a swap's trial asks for thousands of them.
  double error(uint32_t s) const { return error_[s]; }
  double error_without(uint32_t s, int c) const { return first_[s] == c ? second_error_[s] : error_[s]; }

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
  // Whether candidates a and b may cover one sample both: their spheres grown by delta meet in
  // some pose (with a margin far above the gaps' rounding).
  bool may_share(int a, int b) const {
    for (const SphereSet& pose : problem_.spheres) {
      const Sphere &x = pose[size_t(a)], &y = pose[size_t(b)];
      if (!(x.radius > 0) || !(y.radius > 0)) continue;
      const double reach = x.radius + y.radius + 2 * delta_;
      const double margin = 1e-9 * (reach + x.center.lpNorm<Eigen::Infinity>() + y.center.lpNorm<Eigen::Infinity>());
      if ((x.center - y.center).norm() <= reach + margin) return true;
    }
    return false;
  }
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
    error_[s] = a < 0 ? 2 * delta_ : ga;
    second_error_[s] = b < 0 ? 2 * delta_ : gb;
  }

  const CoverProblem& problem_;
  const Coverage& cov_;
  double delta_;
  std::vector<std::pair<uint32_t, uint32_t>> where_;  // sample -> (pose, index)
  std::vector<double> weight_;
  std::vector<uint32_t> by_start_, by_;
  std::vector<char> in_;
  std::vector<int> first_, second_;
  std::vector<double> error_, second_error_;  // the gaps to first_ and second_ (2 delta: none)
};

// Swaps: a sphere for one that covers every sample only it covers, cutting the summed cost of
// the weighted samples' errors most, in rounds while any does; none takes a sample's error past
// `limit`. Returns the swaps made.
//
// A slot's trial reads the states of the samples its sphere and its options cover, and a swap
// changes those of the two spheres' samples alone; so after the first round, a slot whose
// spheres may share no sample with any swapped since its last trial would find again that no
// swap helps, and is not tried (the same swaps as trying it).
template <class Cost>
size_t swap_rounds(CoverState& state, const Coverage& cov, double delta, std::vector<int>& chosen, const Cost& cost,
                   double limit = std::numeric_limits<double>::infinity()) {
  std::vector<std::pair<int, int>> swapped;     // this call's swaps, in order
  std::vector<size_t> tried(chosen.size(), 0);  // swaps made before each slot's last trial
  auto touched = [&](size_t slot, const std::vector<int>& options) {
    for (size_t k = tried[slot]; k < swapped.size(); ++k)
      for (int x : {swapped[k].first, swapped[k].second}) {
        if (state.may_share(chosen[slot], x)) return true;
        for (int c : options)
          if (state.may_share(c, x)) return true;
      }
    return false;
  };
  for (int round = 0; round < 4; ++round) {
    size_t this_round = 0;
    for (size_t slot = 0; slot < chosen.size(); ++slot) {
      const int out = chosen[slot];
      // Samples only `out` covers: a replacement must cover them all. Those `out` is nearest to,
      // in its row's order: they fall back to their second sphere or to the replacement.
      std::vector<uint32_t> critical, nearest;
      for (uint32_t n = cov.start[size_t(out)]; n < cov.start[size_t(out) + 1]; ++n) {
        const uint32_t s = cov.samples[n];
        if (state.first(s) != out) continue;
        nearest.push_back(s);
        if (state.second(s) < 0) critical.push_back(s);
      }
      // Candidates: those covering the first critical sample (every sample of `out` if none).
      const uint32_t anchor = critical.empty() ? cov.samples[cov.start[size_t(out)]] : critical.front();
      std::vector<int> options;
      for (const uint32_t* c = state.covering_begin(anchor); c != state.covering_end(anchor); ++c)
        if (!state.chosen(int(*c))) options.push_back(int(*c));
      if (round > 0 && !touched(slot, options)) continue;
      tried[slot] = swapped.size();
      std::vector<double> change(options.size(), std::numeric_limits<double>::infinity());
      tbb::parallel_for(size_t(0), options.size(), [&](size_t o) {
        const int in = options[o];
        for (uint32_t s : critical)
          if (state.gap(s, in) > delta) return;
        double sum = 0;
        // Samples losing `out` fall back to their second sphere or to `in`.
        for (uint32_t s : nearest) {
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
      swapped.emplace_back(out, options[best]);
      chosen[slot] = options[best];
      ++this_round;
    }
    if (this_round == 0) break;
  }
  return swapped.size();
}

// The weighted samples' median and largest error.
std::pair<double, double> median_and_max(const CoverState& state, size_t samples) {
  std::vector<double> errors;
  for (uint32_t s = 0; s < samples; ++s)
    if (state.weight(s) > 0) errors.push_back(state.error(s));
  return median_and_max_of(std::move(errors));
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
  // Spare budget: the candidate that cuts the total error most (ties to the lowest index), while
  // one does. A cut only shrinks as spheres are added (every error only falls, and so does a
  // sum of smaller terms in the same order), so the cuts counted before bound those now: each
  // round recounts only the leaders until one keeps its cut (lazy greedy, the same choices).
  auto cut_of = [&](size_t c) {
    double sum = 0;
    for (uint32_t n = cov.start[c]; n < cov.start[c + 1]; ++n)
      sum += state.weight(cov.samples[n]) * std::max(0.0, state.error(cov.samples[n]) - state.gap(cov.samples[n], int(c)));
    return sum;
  };
  size_t added = 0;
  if (chosen.size() < max_spheres) {
    std::vector<std::pair<double, int>> first(candidates);  // (cut, -index)
    tbb::parallel_for(size_t(0), candidates, [&](size_t c) { first[c] = {state.chosen(int(c)) ? 0.0 : cut_of(c), -int(c)}; });
    std::priority_queue<std::pair<double, int>> leaders(std::less<std::pair<double, int>>(), std::move(first));
    while (chosen.size() < max_spheres && !leaders.empty() && leaders.top().first > 0) {
      const auto [bound, neg] = leaders.top();
      leaders.pop();
      const double now = cut_of(size_t(-neg));
      if (now < bound) {
        leaders.emplace(now, neg);
        continue;
      }
      state.add(-neg);
      chosen.push_back(-neg);
      ++added;
    }
  }
  size_t swaps = swap_rounds(state, cov, delta, chosen, [](double e) { return e; });
  const size_t median_swaps = lower_median ? median_descent(state, cov, delta, chosen) : 0;
  log.detail("cover improved: " + std::to_string(added) + " spheres added, " + std::to_string(swaps) + " swaps" +
             (lower_median ? ", " + std::to_string(median_swaps) + " for the median" : ""));
}

}  // namespace spx
