#pragma once
// Selection by coverage (sphere-pack's default method, pose-map's joint selection): the
// drivers that turn a tolerance or a budget into covers (candidates.hpp, coverage.hpp and
// set_cover.hpp give the parts), then the improvement of a cover toward the least total error
// and the refinement of its centres off the voxel grid. Since no sample lies inside an
// inscribed sphere, "every vertex covered at delta" is exactly "max vertex-to-union error <=
// delta":
//   tolerance T: the fewest spheres that cover every sample at delta = T;
//   budget N:    the smallest delta whose cover fits in N spheres (least max error at N).
#include <functional>
#include <string>
#include <vector>

#include "core/log.hpp"
#include "pack/candidates.hpp"
#include "pack/coverage.hpp"
#include "pack/set_cover.hpp"

namespace spx {

// Local improvement of a cover at `delta` towards the least total error (the sum over samples
// of the gap to the nearest chosen sphere, which drives the median): spare budget (up to
// `max_spheres`) goes to the candidates that cut the sum most, then each chosen sphere is
// swapped for the candidate that keeps every sample within `delta` and cuts the sum most,
// while any does. The max error never rises above `delta`. `lower_median`: then swaps that
// bring the most weighted samples within the median error (median descent), none raising the
// weighted samples' largest error.
void improve_cover(const CoverProblem& problem, const Coverage& coverage, double delta, size_t max_spheres,
                   std::vector<int>& chosen, Log& log = Log::silent(), bool lower_median = false);

// Refinement off the voxel grid: each sphere's center moves by `step` (then step/2, step/4)
// along the axes where that cuts the total error of the weighted samples (vertices), its radius
// staying `radius_at(center)` (the exact distance: the sphere stays inside by construction),
// and no sample leaving `delta`. `keep_max` (budget mode, whose first aim is the max): the
// moves, along the diagonals too, first cut the weighted errors summed to a high power (the
// largest dominate), down to step/8; then the total and the median, no weighted sample's error
// rising past their largest. One pose (the rest). Returns the moves made.
size_t refine_off_grid(const std::vector<Eigen::Vector3d>& samples, size_t weighted, SphereSet& spheres,
                       const std::function<double(const Eigen::Vector3d&)>& radius_at, double delta, double step,
                       Log& log = Log::silent(), bool keep_max = false);

// The spheres a rest centre becomes in each pose, the rest's first, each radius by its pose's
// rule (inside by construction); false refuses the centre (a radius 0 in some pose).
using PoseSpheresAt = std::function<bool(const Eigen::Vector3d& rest_center, std::vector<Sphere>& in_poses)>;

// The same refinement over several poses at once (pose-map's joint selection): a move of a rest
// centre moves its sphere in every pose (`spheres_at`), and the errors summed are every pose's
// weighted samples' (`samples[p]`, the first `weighted[p]` of them). `centers`: the rest
// centres; `spheres`: per pose, the spheres they make there (updated with them).
size_t refine_jointly(const std::vector<std::vector<Eigen::Vector3d>>& samples, const std::vector<size_t>& weighted,
                      std::vector<Eigen::Vector3d>& centers, std::vector<SphereSet>& spheres,
                      const PoseSpheresAt& spheres_at, double delta, double step, Log& log = Log::silent(),
                      bool keep_max = false);

struct CoverResult {
  std::vector<int> chosen;     // candidate indices
  double delta = 0;            // the coverage distance the cover meets
  double least_max_delta = 0;  // budget mode: the least delta any cover of the budget met
  size_t lower_bound = 0;      // no cover at `delta` has fewer spheres
  // Samples no candidate covers at `delta` (then the tolerance is out of reach): stacked indices,
  // ascending.
  std::vector<uint32_t> uncovered;
  size_t uncoverable() const { return uncovered.size(); }
  double least_reachable = 0;  // the smallest delta at which every sample can be covered
  int evaluations = 0;         // covers solved
  // Tolerance mode: the samples the reduction kept; a cover of them covers every sample.
  std::vector<uint32_t> kept_samples;
};

// Budget mode: after the greedy bisection, this many bisections over the deltas up to
// kSearchReach below greedy's, each cover searched until it fits the budget.
constexpr int kSearchBisections = 4;
constexpr double kSearchReach = 0.3;

// Tolerance mode: the fewest candidates that cover every sample at `delta`. `start`: a cover of
// fewer samples to complete (smallest_cover's warm start; give limits such as kWarmSearch).
CoverResult cover_within(const CoverProblem& problem, double delta, SearchLimits limits = kToleranceSearch,
                         Log& log = Log::silent(), const std::vector<int>& start = {});

// Samples a tolerance leaves out of reach (`which`, stacked indices), covered as near as the
// candidates come: the fewest candidates (greedy) that bring each within the least delta at which
// every one of them can be covered at all, added to `chosen` (past the samples it brings that near
// already). A cover that left them bare would leave their error to chance. Returns how many were
// added; `reach`, where given, is set to that delta (0 where `which` is empty).
size_t cover_out_of_reach(const CoverProblem& problem, const std::vector<uint32_t>& which, std::vector<int>& chosen,
                          double* reach = nullptr);

// What decided a selection's size, and its words in reports and logs (limit_wording).
// `candidates`: a budget the selection did not fill, no other candidate lowering any sample's
// error (set once the selection is done: until then it is `budget`, which the refinement keys on).
// `flat`: the parts out of reach are flat (a stray triangle, a sheet) or have no solid beside them
// (kNoSolidBeside), which no resolution fills.
enum class Limit { tolerance, default_tolerance, resolution, reach, motion, flat, budget, budget_over_tolerance, candidates };
const char* limit_wording(Limit limit);
// The selection ended by meeting its tolerance (given or the default), not by a limit.
inline bool met_tolerance(Limit limit) { return limit == Limit::tolerance || limit == Limit::default_tolerance; }
// Why a surface vertex with no solid on either side of it (MeshQuery::solid_beside) is reached by
// no sphere at any resolution: the one wording sphere-pack's and pose-map's messages share.
constexpr const char* kNoSolidBeside =
    "the winding number is under 1/2 on both sides of the surface there: an open or inward-facing part that encloses "
    "nothing";
// Budget mode, once done: `candidates` where `used` spheres are fewer than the `budget`.
void note_unused_budget(Limit& limited_by, size_t used, size_t budget, Log& log);

// Budget mode's relaxation (cover_with_budget's slack, below).
constexpr double kBudgetSlack = 0.1;
// ... where the centres are then refined off the grid (sphere-pack; pose-map over every pose):
// its median moves make up most of what the tighter relaxation costs the median, and its max
// descent starts lower.
constexpr double kRefinedBudgetSlack = 0.06;

// Both modes as the tools combine them: the fewest spheres within `target` (when > 0), unless
// that exceeds `budget` (when > 0), then the least error for the budget. `limited_by` says
// which decided (the tolerance, the field's resolution or the budget). `budget_slack`: the
// relaxation of budget mode.
CoverResult cover_for(const CoverProblem& problem, double target, size_t budget, Limit& limited_by,
                      Log& log = Log::silent(), double budget_slack = kBudgetSlack);

// Budget mode: the smallest delta (to a relative `precision`) whose cover has at most
// `max_spheres` candidates; then the cover at (1 + slack) times it, improved with the budget
// that leaves (a little more max error for a lower median). `first_delta` (when > 0): where the
// bisection starts, a delta some cover of the budget is known to meet (otherwise it doubles
// from a small one, a table at each doubling).
CoverResult cover_with_budget(const CoverProblem& problem, size_t max_spheres, double slack = kBudgetSlack,
                              double precision = 1e-2, Log& log = Log::silent(), double first_delta = 0);

}  // namespace spx
