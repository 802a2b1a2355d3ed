#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>

#include "core/random.hpp"
#include "pack/set_cover.hpp"
#include "pack/weighted_cover.hpp"

namespace spx {
namespace {

using detail::WeightedCover;

// One search from `chosen` with its own random sequence: the smallest cover met.
std::vector<int> search_from(const Coverage& cov, const Coverage& by, const std::vector<int>& chosen,
                             SearchLimits limits, size_t enough, uint64_t seed) {
  WeightedCover state(cov, by, limits.thorough);  // samples no candidate covers are never bare
  for (int c : chosen) state.add(uint32_t(c), 0);
  std::vector<int> best = chosen;
  SplitMix rng{seed};
  uint32_t tabu = UINT32_MAX;
  for (uint64_t step = 1; step <= limits.steps && best.size() > enough && state.work() < limits.work; ++step) {
    // A cover: keep it if smaller, then search one sphere below it.
    while (state.covers_all()) {
      if (state.members().size() < best.size()) best.assign(state.members().begin(), state.members().end());
      if (state.members().size() <= 1) break;
      state.remove(state.cheapest_member(UINT32_MAX), step);
    }
    if (state.members().size() <= 1) break;
    state.remove(state.cheapest_member(tabu), step);
    const uint32_t sample = state.bare(size_t(rng.next() % state.bare_count()));
    tabu = state.best_adder(sample);
    state.add(tabu, step);
    state.raise_bare_weights();
  }
  if (state.covers_all() && state.members().size() < best.size())
    best.assign(state.members().begin(), state.members().end());
  return best;
}

// Searches run side by side from the same cover, each with its own random sequence.
constexpr size_t kSearches = 2;

}  // namespace

size_t local_search_cover(const Coverage& cov, std::vector<int>& chosen, SearchLimits limits, size_t enough,
                          uint64_t seed) {
  if (chosen.size() <= std::max<size_t>(1, enough) || limits.steps == 0) return 0;
  const Coverage by = covering_candidates(cov);
  // Cheap searches run side by side (one per core here): the first to reach `enough` spheres
  // wins, else the smallest, ties to the first, so the result does not depend on the threads.
  const size_t searches = limits.thorough ? 1 : kSearches;
  std::array<std::vector<int>, kSearches> found;
  tbb::parallel_for(size_t(0), searches, [&](size_t k) {
    found[k] = search_from(cov, by, chosen, limits, enough, seed + k * 0x9E3779B97F4A7C15ull);
  });
  std::vector<int> best = chosen;
  for (size_t k = 0; k < searches; ++k) {
    if (found[k].size() < best.size()) best = found[k];
    if (best.size() <= enough) break;
  }
  const size_t saved = chosen.size() - best.size();
  if (saved > 0) {
    std::sort(best.begin(), best.end());
    chosen = best;
  }
  return saved;
}

}  // namespace spx
