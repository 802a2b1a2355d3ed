#pragma once
// Sphere selection by coverage (sphere-pack's default method). Candidates are inscribed
// spheres: centers at the field's near-medial interior voxels, radius the exact distance to the
// surface (then grown along the normal to the largest such sphere containing it), so every
// candidate lies inside the mesh. Samples are every mesh vertex plus
// area-weighted surface points. A candidate covers a sample within delta of its sphere; since
// no sample lies inside an inscribed sphere, "every vertex covered at delta" is exactly
// "max vertex-to-union error <= delta". A set cover then picks the spheres:
//   tolerance T: the fewest spheres that cover every sample at delta = T;
//   budget N:    the smallest delta whose cover fits in N spheres (least max error at N).
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "core/log.hpp"
#include "core/sphere.hpp"
#include "io/dense_field.hpp"
#include "mesh/inscribed.hpp"
#include "mesh/mesh_query.hpp"

namespace spx {

struct CandidateOptions {
  double min_radius = 0;
  double max_radius = 1e300;
  size_t max_candidates = 12000;  // thinned on a coarser grid past this, deepest kept per cell
  bool field_bounds_radius = false;  // open meshes: the field bounds radii across the holes too
  // Each candidate grown to the largest inscribed sphere containing it (grow_inscribed), so
  // centers off the medial axis by a voxel reach it; closed meshes only (the field's bound
  // across an open mesh's holes holds at voxel centers alone).
  double growth = kDefaultGrowth;
};

// Inscribed candidate spheres from the interior voxels of `field` that lie near its medial
// axis (no face neighbour deeper by half a voxel or more), radii from `mesh`, each grown to the
// largest inscribed sphere containing it (options.growth).
SphereSet inscribed_candidates(const DenseField& field, const MeshQuery& mesh, const CandidateOptions& options);

// Every vertex of `mesh`, then `area_samples` points drawn uniformly by area (seeded).
std::vector<Eigen::Vector3d> surface_samples(const TriMesh& mesh, size_t area_samples, uint64_t seed);

// Which samples each candidate covers at `delta`: gap(sample, sphere) = |p - c| - r <= delta.
// Compressed rows, one per candidate.
struct Coverage {
  std::vector<uint32_t> start;    // candidates + 1 offsets into `samples`
  std::vector<uint32_t> samples;  // ascending within a row
  size_t sample_count = 0;
  size_t row_size(size_t c) const { return start[c + 1] - start[c]; }
};

// The geometry of one cover problem: the points to cover, in one or several poses, and each
// candidate's sphere in those poses. Rows of several poses are stacked: a candidate covers a
// sample of pose k with its sphere in pose k.
struct CoverProblem {
  std::vector<std::vector<Eigen::Vector3d>> samples;  // per pose
  // Per pose: the first `weighted[k]` samples count in the total error that local improvement
  // cuts (the mesh's vertices, where the error is measured); the rest (area samples) only have
  // to stay within delta. Empty: every sample counts.
  std::vector<size_t> weighted;
  std::vector<SphereSet> spheres;                     // per pose, one per candidate (radius 0: absent)
  size_t candidate_count() const { return spheres.empty() ? 0 : spheres.front().size(); }
  size_t sample_count() const;
};

Coverage coverage_at(const CoverProblem& problem, double delta);

// The coverage at every delta up to `max_delta`, computed once: each candidate's samples with
// their gaps. at(delta) equals coverage_at(problem, delta) for any delta <= max_delta.
class GapTable {
 public:
  GapTable(const CoverProblem& problem, double max_delta);
  Coverage at(double delta) const;

 private:
  double max_delta_;
  size_t sample_count_ = 0;
  std::vector<uint32_t> start_, samples_;
  std::vector<double> gaps_;
};

// The same pairs the other way round: for each sample, the candidates that cover it.
Coverage covering_candidates(const Coverage& coverage);

// For each sample, the smallest gap over every candidate: the least delta at which it can be
// covered at all (infinite where no candidate exists).
std::vector<double> least_gaps(const CoverProblem& problem);

// Greedy set cover (most newly covered first, ties to the lower index), then removal of
// spheres every one of whose samples another chosen sphere also covers. Samples no candidate
// covers are skipped (the caller counts them). Returns candidate indices.
std::vector<int> greedy_cover(const Coverage& coverage);

// Local search on a cover: add a candidate, drop every sphere it makes redundant, keep the move
// when that removes two or more. Returns the spheres saved.
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
// and the reduction's `scan` before it (reduce_cover).
struct SearchLimits {
  size_t steps;
  uint64_t work;
  uint32_t scan = UINT32_MAX;
};
// Tolerance mode: about a second on a 5-pose elephant (20000 steps there), 1.5 s at most.
constexpr SearchLimits kToleranceSearch{20000, 2000000000};
// Budget mode searches several covers, densest at small budgets: about a tenth of a second each.
constexpr SearchLimits kBudgetSearch{2000, 150000000, 256};

// Row-weighting local search (after Gao, Weise and Li's RWLS for unicost set cover): from a
// cover, drop the sphere whose loss is least and re-cover a random bare sample with the
// candidate that gains most, raising the weight of every sample left bare at each step so that
// the hard ones steer the search; keeps the smallest cover met. Stops at the limits or once a
// cover of `enough` spheres or fewer is found. Deterministic (`seed`). Returns the spheres saved.
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

// Local improvement of a cover at `delta` towards the least total error (the sum over samples
// of the gap to the nearest chosen sphere, which drives the median): spare budget (up to
// `max_spheres`) goes to the candidates that cut the sum most, then each chosen sphere is
// swapped for the candidate that keeps every sample within `delta` and cuts the sum most,
// while any does. The max error never rises above `delta`.
void improve_cover(const CoverProblem& problem, const Coverage& coverage, double delta, size_t max_spheres,
                   std::vector<int>& chosen, Log& log = Log::silent());

// Refinement off the voxel grid: each sphere's center moves by `step` (then step/2, step/4)
// along the axes where that cuts the total error of the weighted samples (vertices), its radius
// staying `radius_at(center)` (the exact distance: the sphere stays inside by construction),
// and no sample leaving `delta`. One pose (the rest). Returns the moves made.
size_t refine_centers(const std::vector<Eigen::Vector3d>& samples, size_t weighted, SphereSet& spheres,
                      const std::function<double(const Eigen::Vector3d&)>& radius_at, double delta, double step,
                      Log& log = Log::silent());

struct CoverResult {
  std::vector<int> chosen;     // candidate indices
  double delta = 0;            // the coverage distance the cover meets
  double least_max_delta = 0;  // budget mode: the least delta any cover of the budget met
  size_t lower_bound = 0;      // no cover at `delta` has fewer spheres
  size_t uncoverable = 0;      // samples no candidate covers at `delta` (then the tolerance is out of reach)
  double least_reachable = 0;  // the smallest delta at which every sample can be covered
  int evaluations = 0;         // covers solved
};

// The fewest spheres found for `coverage`: the problem reduced (reduce_cover), greedy, shrunk,
// then the row-weighting search, stopping at `enough` spheres. `lower_bound`, when given, gets
// the larger of the two bounds. Returns candidate indices, ascending.
std::vector<int> smallest_cover(const Coverage& coverage, SearchLimits limits, size_t enough, size_t* lower_bound,
                                Log& log = Log::silent());

// Budget mode: after the greedy bisection, this many bisections over the deltas up to
// kSearchReach below greedy's, each cover searched until it fits the budget.
constexpr int kSearchBisections = 3;
constexpr double kSearchReach = 0.15;

// Tolerance mode: the fewest candidates that cover every sample at `delta`.
CoverResult cover_within(const CoverProblem& problem, double delta, SearchLimits limits = kToleranceSearch,
                         Log& log = Log::silent());

// Both modes as the tools combine them: the fewest spheres within `target` (when > 0), unless
// that exceeds `budget` (when > 0), then the least error for the budget. `limited_by` says
// which decided: "met the tolerance", "the field's resolution (...)", "max_spheres (...)".
CoverResult cover_for(const CoverProblem& problem, double target, size_t budget, std::string& limited_by,
                      Log& log = Log::silent());

// Budget mode: the smallest delta (to a relative `precision`) whose cover has at most
// `max_spheres` candidates; then the cover at (1 + slack) times it, improved with the budget
// that leaves (a little more max error for a lower median).
constexpr double kBudgetSlack = 0.15;
CoverResult cover_with_budget(const CoverProblem& problem, size_t max_spheres, double slack = kBudgetSlack,
                              double precision = 1e-2, Log& log = Log::silent());

}  // namespace spx
