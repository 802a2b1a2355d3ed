#include "pack/cover.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

#include "core/format.hpp"

namespace spx {
namespace {

// Budget mode's greedy bisection: the first delta tried, a quarter past the least at which
// every sample can be covered at all; and at most this many covers solved in it (doubling,
// then halving the interval).
constexpr double kFirstDeltaOverReach = 1.25;
// ... and no less than this part of the samples' diagonal: with a candidate at every sample the
// least reachable delta is float rounding, and doubling from there would build table after
// table no budget a host runs fits.
constexpr double kFirstDeltaFloor = 5e-3;

double diagonal_of(const CoverProblem& problem) {
  Eigen::AlignedBox3d box;
  for (const auto& pose : problem.samples)
    for (const auto& p : pose) box.extend(p);
  return box.isEmpty() ? 0 : box.diagonal().norm();
}
constexpr int kMaxBudgetCovers = 60;

// Budget mode's best cover so far: its candidates and the delta it meets. (Its coverage is read
// from the table again at the end: on a long clip each coverage holds hundreds of megabytes.)
void keep_cover(CoverResult& best, std::vector<int> chosen, double delta) {
  best.chosen = std::move(chosen);
  best.delta = delta;
}

// Counts a cover of budget mode at delta. They take seconds each on a long clip: the one under
// way is shown on a terminal.
void count_cover(CoverResult& best, const Log& log, size_t max_spheres, double delta) {
  ++best.evaluations;
  log.begin("covering for " + std::to_string(max_spheres) + " spheres: cover " + std::to_string(best.evaluations) +
            ", delta " + num(delta));
}

// Budget mode's start: greedy covers from a small delta, doubled (a table each time) until one
// fits the budget, then bisected to `precision`; the last table is left in `table`.
void greedy_bisection(const CoverProblem& problem, size_t max_spheres, double reach, double precision, double lo_start,
                      std::unique_ptr<GapTable>& table, CoverResult& best, const Log& log) {
  auto solve = [&](double delta) {
    count_cover(best, log, max_spheres, delta);
    return greedy_cover(table->at(delta));
  };
  // Below the largest least gap some sample cannot be covered; above it, grow until it fits.
  double lo = lo_start, hi = std::max({lo_start * kFirstDeltaOverReach, kFirstDeltaFloor * diagonal_of(problem), 1e-12});
  table = std::make_unique<GapTable>(problem, hi * reach);
  std::vector<int> cover = solve(hi);
  while (cover.size() > max_spheres && best.evaluations < kMaxBudgetCovers) {
    lo = hi;
    hi *= 2;
    table = std::make_unique<GapTable>(problem, hi * reach);
    cover = solve(hi);
  }
  keep_cover(best, std::move(cover), hi);
  while (hi - lo > precision * hi && best.evaluations < kMaxBudgetCovers) {
    const double mid = 0.5 * (lo + hi);
    std::vector<int> c = solve(mid);
    if (c.size() <= max_spheres) {
      hi = mid;
      keep_cover(best, std::move(c), mid);
      table->shrink(hi * reach);  // nothing past it is asked from here on
    } else {
      lo = mid;
    }
  }
}

double largest_finite(const std::vector<double>& values) {
  double out = 0;
  for (double v : values)
    if (std::isfinite(v)) out = std::max(out, v);
  return out;
}

}  // namespace

CoverResult cover_within(const CoverProblem& problem, double delta, SearchLimits limits, Log& log,
                         const std::vector<int>& start) {
  CoverResult r;
  r.delta = delta;
  const Coverage cov = coverage_at(problem, delta);
  r.chosen = smallest_cover(cov, limits, 0, &r.lower_bound, log, start, &r.kept_samples);
  improve_cover(problem, cov, delta, r.chosen.size(), r.chosen, log);
  const std::vector<uint32_t> bare = uncovered_samples(cov);
  r.uncovered = bare;
  // A tolerance out of reach: the least delta that would do is set by the bare samples alone
  // (every other is within delta).
  r.least_reachable = std::max(delta, largest_finite(least_gaps_of(problem, bare)));
  r.evaluations = 1;
  log.detail("cover at " + num(delta) + ": " + std::to_string(r.chosen.size()) + " spheres (at least " +
             std::to_string(r.lower_bound) + "), " + std::to_string(cov.samples.size()) + " pairs");
  return r;
}

size_t cover_out_of_reach(const CoverProblem& problem, const std::vector<uint32_t>& which, std::vector<int>& chosen,
                          double* reach_out) {
  if (reach_out) *reach_out = 0;
  if (which.empty()) return 0;
  const double reach = largest_finite(least_gaps_of(problem, which));
  if (reach_out) *reach_out = reach;
  // Those samples alone, each in its pose, against every candidate (none merged into another):
  // the coverage rule at `reach`.
  CoverProblem out_of_reach;
  out_of_reach.spheres = problem.spheres;
  out_of_reach.samples.resize(problem.samples.size());
  size_t pose = 0, first = 0;
  for (uint32_t s : which) {  // ascending
    while (s >= first + problem.samples[pose].size()) first += problem.samples[pose++].size();
    out_of_reach.samples[pose].push_back(problem.samples[pose][s - first]);
  }
  const Coverage rows = coverage_at(out_of_reach, reach);
  // The fewest more candidates for the samples no chosen one covers there (the others' columns
  // left empty: greedy skips them).
  std::vector<char> covered(rows.sample_count, 0);
  for (int c : chosen)
    for (uint32_t n = rows.start[size_t(c)]; n < rows.start[size_t(c) + 1]; ++n) covered[rows.samples[n]] = 1;
  Coverage bare;
  bare.sample_count = rows.sample_count;
  bare.start.assign(rows.start.size(), 0);
  for (size_t c = 0; c + 1 < rows.start.size(); ++c) {
    for (uint32_t n = rows.start[c]; n < rows.start[c + 1]; ++n)
      if (!covered[rows.samples[n]]) bare.samples.push_back(rows.samples[n]);
    bare.start[c + 1] = uint32_t(bare.samples.size());
  }
  const std::vector<int> added = greedy_cover(std::move(bare));
  chosen.insert(chosen.end(), added.begin(), added.end());
  std::sort(chosen.begin(), chosen.end());
  return added.size();
}

const char* limit_wording(Limit limit) {
  switch (limit) {
    case Limit::tolerance: return "met the tolerance";
    case Limit::default_tolerance: return "met the default tolerance";
    case Limit::resolution: return "the field's resolution (some samples are out of reach)";
    case Limit::reach: return "samples no inscribed sphere reaches (sharp features under the least radius)";
    case Limit::motion: return "vertices no skinned sphere reaches in every frame (where the skin folds)";
    case Limit::flat:
      return "flat parts, or surface with no solid beside it (a stray triangle, a sheet, or an open or inward-facing "
             "part that encloses nothing there holds no sphere at any resolution)";
    case Limit::budget: return "max_spheres";
    case Limit::budget_over_tolerance: return "max_spheres (tighter than the tolerance)";
    case Limit::candidates: return "the candidates (no other lowered any sample's error; fewer spheres than max_spheres)";
  }
  return "";
}

void note_unused_budget(Limit& limited_by, size_t used, size_t budget, Log& log) {
  if (limited_by != Limit::budget || used >= budget) return;
  limited_by = Limit::candidates;
  // Said, so that nobody asks for more.
  log.info(std::to_string(used) + " of the " + std::to_string(budget) +
           " spheres asked: no other candidate lowered any sample's error");
}

CoverResult cover_for(const CoverProblem& problem, double target, size_t budget, Limit& limited_by, Log& log,
                      double budget_slack) {
  CoverResult cover;
  if (target > 0) {
    cover = cover_within(problem, target, kToleranceSearch, log);
    limited_by = cover.uncoverable() > 0 ? Limit::resolution : Limit::tolerance;
  }
  if (budget > 0 && (!(target > 0) || cover.chosen.size() > budget)) {
    cover = cover_with_budget(problem, budget, budget_slack, 1e-2, log);
    limited_by = target > 0 ? Limit::budget_over_tolerance : Limit::budget;
  }
  return cover;
}

CoverResult cover_with_budget(const CoverProblem& problem, size_t max_spheres, double slack, double precision,
                              Log& log, double first_delta) {
  CoverResult best;
  const std::vector<double> gaps = least_gaps(problem);
  const double lo_start = largest_finite(gaps);
  best.least_reachable = lo_start;
  // Each table holds the pairs up to (1 + slack) times its delta: the relaxed cover at the end
  // comes from the same table.
  const double reach = 1 + std::max(slack, 0.0);
  std::unique_ptr<GapTable> table;
  // Where a cover of the budget is known at first_delta, the search finds one there: greedy's
  // bisection (a table at each doubling) is not needed to start below.
  if (first_delta > lo_start) {
    table = std::make_unique<GapTable>(problem, first_delta * reach);
    count_cover(best, log, max_spheres, first_delta);
    std::vector<int> c = smallest_cover(table->at(first_delta), kBudgetSearch, max_spheres, nullptr, log);
    if (c.size() <= max_spheres) keep_cover(best, std::move(c), first_delta);
  }
  if (best.chosen.empty()) greedy_bisection(problem, max_spheres, reach, precision, lo_start, table, best, log);
  // The row-weighting search fits the budget at a smaller delta than greedy does: bisect
  // below greedy's delta, each cover searched until it fits.
  double lo = std::max(lo_start, (1 - kSearchReach) * best.delta);
  for (int step = 0; step < kSearchBisections && best.delta - lo > precision * best.delta; ++step) {
    const double mid = 0.5 * (lo + best.delta);
    count_cover(best, log, max_spheres, mid);
    std::vector<int> c = smallest_cover(table->at(mid), kBudgetSearch, max_spheres, nullptr, log);
    if (c.size() <= max_spheres)
      keep_cover(best, std::move(c), mid);
    else
      lo = mid;
  }
  best.least_max_delta = best.delta;
  if (slack > 0) {
    // A little more max error buys a lower median: the cover at the relaxed delta is smaller,
    // and improve_cover spends the budget it leaves on the total error, then on the median.
    const double relaxed = best.delta * (1 + slack);
    count_cover(best, log, max_spheres, relaxed);
    std::vector<int> c = smallest_cover(table->at(relaxed), kBudgetSearch, 0, nullptr);
    if (c.size() <= max_spheres) keep_cover(best, std::move(c), relaxed);
  }
  if (best.chosen.size() > max_spheres) best.chosen.resize(max_spheres);  // never over budget
  const Coverage best_cov = table->at(best.delta);
  improve_cover(problem, best_cov, best.delta, max_spheres, best.chosen, log, true);
  best.lower_bound = lower_bound_of(best_cov, best.chosen.size());
  best.uncovered = uncovered_samples(best_cov);
  log.detail("budget " + std::to_string(max_spheres) + ": delta " + num(best.delta) + " with " +
             std::to_string(best.chosen.size()) + " spheres after " + std::to_string(best.evaluations) + " covers");
  return best;
}

}  // namespace spx
