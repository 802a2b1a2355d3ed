// Lower bounds on any cover's size (declared in set_cover.hpp): the independent samples' and the
// Lagrangian relaxation's.
#include "pack/set_cover.hpp"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>
#include <utility>

namespace spx {
namespace {

// The Lagrangian bound: pairs visited in all by its steps (a dense budget cover's bound would
// otherwise cost more than its search); steps without a better bound before the step halves;
// the value Polyak's rule steps toward, a little above the known cover's size.
constexpr size_t kLagrangianPairs = size_t(4e8);
constexpr int kStallSteps = 15;
constexpr double kPolyakTarget = 1.05;

}  // namespace

// One row's sum is a chain of dependent subtractions, each waiting for the one before, so four
// rows are summed side by side (a lane that ends takes the next row).
void detail::reduced_costs(const Coverage& cov, const double* u, size_t first, size_t end, double* reduced) {
  constexpr int kLanes = 4;
  const uint32_t* pairs = cov.samples.data();
  std::array<const uint32_t*, kLanes> at{}, stop{};
  std::array<double, kLanes> r{};
  std::array<size_t, kLanes> row{};
  size_t next = first;
  // A row's rest subtracted one entry at a time, in its order.
  auto finish = [&](double sum, const uint32_t* p, const uint32_t* stop_at) {
    for (; p != stop_at; ++p) sum -= u[*p];
    return sum;
  };
  auto take = [&](int k) {
    row[k] = next;
    at[k] = pairs + cov.start[next];
    stop[k] = pairs + cov.start[next + 1];
    r[k] = 1;
    ++next;
  };
  if (end - first < size_t(kLanes)) {
    for (size_t c = first; c < end; ++c) reduced[c] = finish(1, pairs + cov.start[c], pairs + cov.start[c + 1]);
    return;
  }
  for (int k = 0; k < kLanes; ++k) take(k);
  while (true) {
    // As many steps as the shortest lane has left, on all four; then the lanes that ended.
    size_t steps = size_t(stop[0] - at[0]);
    for (int k = 1; k < kLanes; ++k) steps = std::min(steps, size_t(stop[k] - at[k]));
    double r0 = r[0], r1 = r[1], r2 = r[2], r3 = r[3];
    const uint32_t *a0 = at[0], *a1 = at[1], *a2 = at[2], *a3 = at[3];
    for (size_t n = 0; n < steps; ++n) {
      r0 -= u[a0[n]];
      r1 -= u[a1[n]];
      r2 -= u[a2[n]];
      r3 -= u[a3[n]];
    }
    r = {r0, r1, r2, r3};
    for (int k = 0; k < kLanes; ++k) at[k] += steps;
    bool rows_left = true;
    for (int k = 0; k < kLanes && rows_left; ++k) {
      if (at[k] != stop[k]) continue;
      reduced[row[k]] = r[k];
      rows_left = next < end;
      if (rows_left) take(k);
      else row[k] = SIZE_MAX;
    }
    if (!rows_left) break;
  }
  // No rows left to take: the lanes still open finish one at a time.
  for (int k = 0; k < kLanes; ++k)
    if (row[k] != SIZE_MAX) reduced[row[k]] = finish(r[k], at[k], stop[k]);
}

// The larger of the two lower bounds. On a reduced problem too: the reduction keeps the optimum
// of the problem and of its LP relaxation, so its bounds hold for the original.
// The Lagrangian's steps are capped at kLagrangianPairs pairs visited in all (a dense budget cover's
// bound would otherwise cost more than its search).
size_t lower_bound_of(const Coverage& cov, size_t upper) {
  const int steps = int(std::clamp<size_t>(kLagrangianPairs / std::max<size_t>(cov.samples.size(), 1), 20, 200));
  return std::max(cover_lower_bound(cov), lagrangian_bound(cov, upper, steps));
}

size_t cover_lower_bound(const Coverage& cov) {
  const size_t candidates = cov.start.size() - 1;
  const Coverage covering = covering_candidates(cov);
  const std::vector<uint32_t>& start = covering.start;
  const std::vector<uint32_t>& by = covering.samples;
  // Most constrained samples first; a pick blocks every sample a candidate of it covers.
  std::vector<uint32_t> order(cov.sample_count);
  std::iota(order.begin(), order.end(), 0u);
  std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) {
    return start[a + 1] - start[a] < start[b + 1] - start[b];
  });
  std::vector<char> blocked(cov.sample_count, 0), used(candidates, 0);
  size_t picked = 0;
  for (uint32_t s : order) {
    if (blocked[s] || start[s] == start[s + 1]) continue;
    ++picked;
    for (uint32_t n = start[s]; n < start[s + 1]; ++n) {
      const uint32_t c = by[n];
      if (used[c]) continue;
      used[c] = 1;
      for (uint32_t m = cov.start[c]; m < cov.start[c + 1]; ++m) blocked[cov.samples[m]] = 1;
    }
  }
  return picked;
}

size_t lagrangian_bound(const Coverage& cov, size_t upper, int steps) {
  const size_t candidates = cov.start.size() - 1, samples = cov.sample_count;
  std::vector<char> coverable(samples, 0);
  for (uint32_t s : cov.samples) coverable[s] = 1;
  // Start: each sample's multiplier the best 1/|column| among the candidates covering it.
  std::vector<double> u(samples, 0.0);
  for (size_t c = 0; c < candidates; ++c)
    for (uint32_t n = cov.start[c]; n < cov.start[c + 1]; ++n) {
      const double share = 1.0 / double(cov.row_size(c));
      if (u[cov.samples[n]] == 0 || share < u[cov.samples[n]]) u[cov.samples[n]] = share;
    }
  // Subgradient steps by Polyak's rule toward the best cover known (`upper`).
  std::vector<int> hits(samples, 0);
  tbb::enumerable_thread_specific<std::vector<int>> local_hits([&] { return std::vector<int>(samples, 0); });
  std::vector<double> reduced(candidates);
  double best = 0, lambda = 2.0;
  int since_better = 0;
  for (int step = 0; step < steps && lambda > 1e-3; ++step) {
    double value = 0;
    for (size_t s = 0; s < samples; ++s) value += u[s];
    std::fill(hits.begin(), hits.end(), 0);
    // Each candidate's reduced cost, and how often those of negative cost cover each sample, on
    // both cores: a block's rows are counted while they are still in the cache, into its
    // thread's own counts, added up after (integers: the same whatever the threads).
    tbb::parallel_for(tbb::blocked_range<size_t>(0, candidates, 256), [&](const tbb::blocked_range<size_t>& range) {
      detail::reduced_costs(cov, u.data(), range.begin(), range.end(), reduced.data());
      std::vector<int>& own = local_hits.local();
      for (size_t c = range.begin(); c != range.end(); ++c)
        if (reduced[c] < 0)
          for (uint32_t n = cov.start[c]; n < cov.start[c + 1]; ++n) ++own[cov.samples[n]];
    });
    for (std::vector<int>& own : local_hits)
      for (size_t s = 0; s < samples; ++s) hits[s] += std::exchange(own[s], 0);
    for (size_t c = 0; c < candidates; ++c)
      if (reduced[c] < 0) value += reduced[c];  // in order; an empty row's is 1
    if (value > best + 1e-9) {
      best = value;
      since_better = 0;
    } else if (++since_better >= kStallSteps) {
      lambda /= 2;
      since_better = 0;
    }
    if (std::ceil(best - 1e-6) >= double(upper)) break;  // the cover is optimal
    double norm = 0;
    for (size_t s = 0; s < samples; ++s)
      if (coverable[s]) {
        const double g = 1.0 - hits[s];
        if (g > 0 || u[s] > 0) norm += g * g;
      }
    if (norm == 0) break;
    const double t = lambda * (kPolyakTarget * double(upper) - value) / norm;
    for (size_t s = 0; s < samples; ++s)
      if (coverable[s]) u[s] = std::max(0.0, u[s] + t * (1.0 - hits[s]));
  }
  return size_t(std::max(0.0, std::ceil(best - 1e-6)));
}

}  // namespace spx
