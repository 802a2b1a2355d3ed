#pragma once
// The set cover itself, free of geometry: candidates are rows of the samples they cover. The
// reduction, greedy, the add-one-drop-two shrink, the row-weighting search, the fewest spheres
// found from them all, and lower bounds on any cover's size. Tested against brute force.
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstdint>
#include <utility>
#include <vector>

#include "core/log.hpp"

namespace spx {

// Which samples each candidate covers: compressed rows, one per candidate.
struct Coverage {
  std::vector<uint32_t> start;    // candidates + 1 offsets into `samples`
  std::vector<uint32_t> samples;  // ascending within a row
  size_t sample_count = 0;
  size_t row_size(size_t c) const { return start[c + 1] - start[c]; }
};

// The samples no candidate covers, ascending.
std::vector<uint32_t> uncovered_samples(const Coverage& coverage);

// The same pairs the other way round: for each sample, the candidates that cover it.
Coverage covering_candidates(const Coverage& coverage);

// Pairs given row by row (`row(r)`: the columns of row r, any iterable of uint32_t) as
// compressed rows over the `columns`: for each column, the rows listing it, ascending. A
// counting sort in chunks of rows side by side; the same result whatever the threads.
template <class Row>
Coverage transposed(size_t rows, size_t columns, Row&& row) {
  const size_t chunks = std::clamp<size_t>(rows / 4096, 1, 16);
  auto chunk_rows = [&](size_t k) { return std::make_pair(rows * k / chunks, rows * (k + 1) / chunks); };
  // Each chunk's count per column, then where its first entry of that column goes.
  std::vector<std::vector<uint32_t>> at(chunks, std::vector<uint32_t>(columns, 0));
  tbb::parallel_for(size_t(0), chunks, [&](size_t k) {
    const auto [first, end] = chunk_rows(k);
    for (size_t r = first; r < end; ++r)
      for (uint32_t c : row(r)) ++at[k][c];
  });
  Coverage out;
  out.sample_count = rows;
  out.start.assign(columns + 1, 0);
  for (size_t c = 0; c < columns; ++c) {
    uint32_t next = out.start[c];
    for (size_t k = 0; k < chunks; ++k) {
      const uint32_t count = at[k][c];
      at[k][c] = next;
      next += count;
    }
    out.start[c + 1] = next;
  }
  out.samples.resize(out.start.back());
  tbb::parallel_for(size_t(0), chunks, [&](size_t k) {
    const auto [first, end] = chunk_rows(k);
    for (size_t r = first; r < end; ++r)
      for (uint32_t c : row(r)) out.samples[at[k][c]++] = uint32_t(r);
  });
  return out;
}

// Greedy set cover (most newly covered first, ties to the lower index), then removal of
// spheres every one of whose samples another chosen sphere also covers. Samples no candidate
// covers are skipped (the caller counts them). `start`: a partial cover to complete (a cover
// of fewer samples, repaired). Returns candidate indices.
std::vector<int> greedy_cover(const Coverage& coverage, const std::vector<int>& start = {});
// The same, using `coverage` up: each row keeps its samples, in another order.
std::vector<int> greedy_cover(Coverage&& coverage, const std::vector<int>& start = {});

// Local search on a cover, in candidate order, up to three passes: add a candidate, drop in turn
// each chosen sphere it could make redundant (it covers every sample only that sphere covers)
// that is then redundant, keep the move when two or more go. Returns the moves kept; a changed
// cover is returned ascending.
size_t shrink_cover(const Coverage& coverage, std::vector<int>& chosen);

// The same cover problem made smaller without changing its optimum: a sample whose candidates
// include all of another's is dropped (covering the other covers it), then a candidate whose
// samples another candidate also covers is dropped. Samples no candidate covers are dropped.
// A sample (candidate) whose check would scan more than `scan` others is kept unchecked: on
// dense problems the full check costs more than the search it speeds up.
struct ReducedCover {
  Coverage coverage;
  std::vector<uint32_t> candidate;  // reduced candidate -> original index
  std::vector<uint32_t> sample;     // reduced sample -> original index
};
ReducedCover reduce_cover(const Coverage& coverage, uint32_t scan = UINT32_MAX);

// How long a row-weighting search may run: at most `steps` steps and `work` entries of the
// coverage visited (on dense problems, a large delta or few spheres, each step costs more);
// the reduction's `scan` before it (reduce_cover); and whether a dropped candidate is free to
// come back after any change in how often its samples are covered (`thorough`: each step costs
// several times more) or only once one of them turned bare or covered.
struct SearchLimits {
  size_t steps;
  uint64_t work;
  uint32_t scan = UINT32_MAX;
  bool thorough = false;
};
// Tolerance mode: about half a second on the elephant's 5 poses, two searches side by side.
constexpr SearchLimits kToleranceSearch{30000, 2000000000};
// Budget mode searches several short covers, densest at small budgets: about a tenth of a
// second each, one thorough search (a second beside it moved the frontier's rows both ways).
constexpr SearchLimits kBudgetSearch{2000, 150000000, 256, true};

// Row-weighting local search (after Gao, Weise and Li's RWLS for unicost set cover): from a
// cover, drop the sphere whose loss is least and re-cover a random bare sample with the
// candidate that gains most, raising the weight of every sample left bare at each step so that
// the hard ones steer the search; keeps the smallest cover met. Stops at the limits or once a
// cover of `enough` spheres or fewer is found. Unless thorough, two searches run side by side,
// the first from `seed`; the first to reach `enough` wins, else the smaller. Deterministic
// whatever the threads. Returns the spheres saved.
size_t local_search_cover(const Coverage& coverage, std::vector<int>& chosen, SearchLimits limits, size_t enough = 0,
                          uint64_t seed = 1);

// A lower bound on any cover's size: samples no two of which one candidate covers together.
size_t cover_lower_bound(const Coverage& coverage);

// The Lagrangian relaxation's lower bound on the number of spheres in any cover (subgradient
// optimisation over the samples' multipliers, steps by Polyak's rule toward `upper`, the size of
// a known cover; a fixed number of steps so the result is deterministic; rounded up, covers
// being whole spheres). Never above the LP relaxation's optimum; usually well above
// cover_lower_bound.
size_t lagrangian_bound(const Coverage& coverage, size_t upper, int steps = 200);

namespace detail {
// The Lagrangian bound's inner step: for candidates first..end, 1 minus the multipliers `u` of
// the samples in its row, subtracted in the row's order, into `reduced` (indexed by candidate).
// Several rows are summed side by side; the bits are those of one row at a time.
void reduced_costs(const Coverage& coverage, const double* u, size_t first, size_t end, double* reduced);
}  // namespace detail

// The larger of cover_lower_bound and lagrangian_bound (its steps capped on dense problems).
size_t lower_bound_of(const Coverage& coverage, size_t upper);

// The fewest spheres found for `coverage`: the problem reduced (reduce_cover), greedy, shrunk,
// then the row-weighting search, stopping at `enough` spheres. `lower_bound`, when given, gets
// the larger of the two bounds. `start`: a cover of fewer samples to complete (warm start)
// rather than starting from nothing. `kept_samples`, when given, gets the samples the reduction
// kept (any cover of those covers every sample), ascending. Returns candidate indices, ascending.
std::vector<int> smallest_cover(const Coverage& coverage, SearchLimits limits, size_t enough, size_t* lower_bound,
                                Log& log = Log::silent(), const std::vector<int>& start = {},
                                std::vector<uint32_t>* kept_samples = nullptr);
// A warm start's search: short and one thorough search, so that the cover stays near the one
// it started from (two cheap ones side by side moved it further: on 48 frames of the elephant's
// walk 9 rounds of checks instead of 6, 5 spheres fewer for 20 % more time).
constexpr SearchLimits kWarmSearch{2000, 200000000, UINT32_MAX, true};

}  // namespace spx
