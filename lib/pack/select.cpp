#include "pack/select.hpp"

#include <algorithm>
#include <functional>
#include <tuple>

#include "core/error.hpp"
#include "core/format.hpp"
#include "mesh/union_distance.hpp"
#include "pack/median_descent.hpp"

namespace spx {
namespace {

// Budget mode, `rounds` times: the budget covered again from every candidate and every set
// refined so far (the last one a cover at its largest gap, where the bisection starts), then
// refined; the best set (kept_over) is kept, its cover with it. A refined sphere sits where no
// voxel or sample offered one, so the cover can pair it with others it could not before, and
// the refinement descends again from another start.
void polish(const CoverProblem& problem, size_t budget, CoverSelection& out,
            const std::function<double(const Eigen::Vector3d&)>& radius_at, double step, int rounds, Log& log) {
  CoverProblem again = problem;
  again.spheres = {out.offered};
  SphereSet current = out.spheres;
  UnionGaps now = union_gaps(problem.samples[0], problem.weighted[0], current), best = now;
  for (int round = 1; round <= rounds; ++round) {
    again.spheres[0].insert(again.spheres[0].end(), current.begin(), current.end());
    CoverResult cover = cover_with_budget(again, budget, kRefinedBudgetSlack, 1e-2, log, now.largest);
    current.clear();
    for (int c : cover.chosen) current.push_back(again.spheres[0][size_t(c)]);
    refine_off_grid(again.samples[0], again.weighted[0], current, radius_at, cover.delta, step, log, true);
    now = union_gaps(again.samples[0], again.weighted[0], current);
    log.detail("polish " + std::to_string(round) + ": vertex error max " + num(now.max) + ", median " + num(now.median) +
               " (kept so far: " + num(best.max) + ", " + num(best.median) + ")");
    if (!kept_over(now, best)) continue;
    best = now;
    out.spheres = current;
    out.cover = std::move(cover);
    out.polished = size_t(round);
  }
}

}  // namespace

UnionGaps union_gaps(const std::vector<Eigen::Vector3d>& samples, size_t weighted, const SphereSet& spheres) {
  const std::vector<double> gap = union_signed_distance(samples, spheres);
  UnionGaps out;
  out.largest = *std::max_element(gap.begin(), gap.end());
  std::tie(out.median, out.max) = detail::median_and_max_of({gap.begin(), gap.begin() + long(weighted)});
  return out;
}

bool kept_over(const UnionGaps& a, const UnionGaps& b) { return a.max <= b.max && a.max * a.median < b.max * b.median; }

namespace {
// No candidate at all, said as greedy packing says it: the deepest voxel against the least radius.
[[noreturn]] void fail_no_candidates(const DenseField& field, double min_radius) {
  double deepest = 0;
  for (float v : field.values) deepest = std::max(deepest, -double(v));
  if (!(deepest > 0)) fail_input("", "no inscribed sphere fits: the field holds no interior voxel");
  fail_input("", "no inscribed sphere fits: the largest interior distance, " + num(deepest) + ", is " +
                     (deepest < min_radius ? "below" : "near") + " the min radius " + num(min_radius));
}
}  // namespace

// Selection by coverage: inscribed candidates, samples on the surface, a set cover for the
// tolerance or the budget, then the centers refined off the grid.
CoverSelection select_by_cover(const DenseField& field, const MeshQuery& mesh, const SpherePackOptions& opt, Log& log) {
  if (!(opt.tolerance > 0) && opt.pack.max_spheres == 0)
    fail_option("tolerance", "give a tolerance (a length) or a sphere budget: the cover method needs one");
  CoverSelection out;
  CoverProblem problem;
  {
    StageTimer t(log, "candidates");
    const CandidateOptions limits = candidate_options(opt.pack);
    problem.spheres.push_back(inscribed_candidates(field, mesh, limits));
    out.voxel_candidates = problem.spheres[0].size();
    const SurfaceSamples samples = sample_surface(mesh.surface(), opt.area_samples, opt.seed);
    if (opt.tangent_candidates) {
      const TangentCandidates tangent = tangent_candidates(mesh, mesh.surface(), samples, field, deepest_radius(field), limits);
      problem.spheres[0].insert(problem.spheres[0].end(), tangent.spheres.begin(), tangent.spheres.end());
      out.touching_samples = tangent.touching;
      out.unreached_samples = tangent.unreached;
      problem.merge = kCandidateMerge;
    }
    problem.samples.push_back(samples.points);
    problem.weighted.push_back(mesh.surface().vertices.size());
  }
  const SphereSet& candidates = problem.spheres[0];
  if (candidates.empty()) fail_no_candidates(field, opt.pack.min_radius);
  out.candidates = candidates.size();
  out.samples = problem.sample_count();
  // The centres are refined off the grid after the cover (below), unless the field bounds the radii.
  const bool refined = !opt.pack.field_bounds_radius;
  {
    StageTimer t(log, "cover");
    out.target = opt.tolerance;
    const double slack = refined ? kRefinedBudgetSlack : kBudgetSlack;
    out.cover = cover_for(problem, out.target, opt.pack.max_spheres, out.limited_by, log, slack);
    if (out.limited_by == Limit::resolution)
      out.out_of_reach_added = cover_out_of_reach(problem, out.cover.uncovered, out.cover.chosen);
  }
  // Where a sample's own candidate reaches it, the tolerance does not wait on the field (but
  // across an open mesh's holes every radius is the field's bound, which a finer field raises).
  if (opt.tangent_candidates && !opt.pack.field_bounds_radius && out.limited_by == Limit::resolution)
    out.limited_by = Limit::reach;
  // pose-map selects over every frame from the pool: the voxels' candidates and those of the
  // samples' that this cover chose (every sample's, carried through every frame, would
  // multiply its work; each frame offers its own near its far samples).
  out.pool.assign(candidates.begin(), candidates.begin() + long(out.voxel_candidates));
  for (int c : out.cover.chosen) {
    out.spheres.push_back(candidates[size_t(c)]);
    if (size_t(c) >= out.voxel_candidates) out.pool.push_back(candidates[size_t(c)]);
  }
  out.offered = std::move(problem.spheres[0]);  // the cover is done with them
  if (refined) {
    // Off the voxel grid: the radius stays the exact distance, so spheres stay inside. (An
    // open mesh's radii also depend on the field across its holes: its centers stay put.)
    StageTimer t(log, "refine");
    const double max_radius = opt.pack.max_radius;
    // Budget mode's first aim is the max: the refinement does not trade it for the total.
    const bool budget = out.limited_by == Limit::budget || out.limited_by == Limit::budget_over_tolerance;
    const auto radius_at = [&](const Eigen::Vector3d& c) {
      return mesh.inside(c) ? std::min(max_radius, mesh.distance(c)) : 0.0;
    };
    const double step = 0.5 * field.shape.voxel_size;
    refine_off_grid(problem.samples[0], problem.weighted[0], out.spheres, radius_at, out.cover.delta, step, log, budget);
    if (budget) polish(problem, opt.pack.max_spheres, out, radius_at, step, opt.polish_rounds, log);
  }
  // What the kept cover chose from: the field's voxels, the samples' tangent balls, or (polished)
  // an earlier refinement's spheres.
  for (int c : out.cover.chosen) {
    out.chosen_tangent += size_t(c) >= out.voxel_candidates && size_t(c) < out.offered.size();
    out.chosen_refined += size_t(c) >= out.offered.size();
  }
  // Largest first (what a host culls by), ties in candidate order.
  std::stable_sort(out.spheres.begin(), out.spheres.end(),
                   [](const Sphere& a, const Sphere& b) { return a.radius > b.radius; });
  note_unused_budget(out.limited_by, out.spheres.size(), opt.pack.max_spheres, log);
  return out;
}

}  // namespace spx
