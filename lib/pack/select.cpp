#include "pack/select.hpp"

#include <algorithm>

#include "core/error.hpp"

namespace spx {

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
  if (candidates.empty()) fail_input("", "no inscribed sphere fits: the field holds no interior voxel");
  out.candidates = candidates.size();
  out.samples = problem.sample_count();
  // The centres are refined off the grid after the cover (below), unless the field bounds the radii.
  const bool refined = !opt.pack.field_bounds_radius;
  {
    StageTimer t(log, "cover");
    out.target = opt.tolerance;
    const double slack = refined ? kRefinedBudgetSlack : kBudgetSlack;
    out.cover = cover_for(problem, out.target, opt.pack.max_spheres, out.limited_by, log, slack);
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
    if (size_t(c) < out.voxel_candidates) continue;
    ++out.chosen_tangent;
    out.pool.push_back(candidates[size_t(c)]);
  }
  out.offered = std::move(problem.spheres[0]);  // the cover is done with them
  if (refined) {
    // Off the voxel grid: the radius stays the exact distance, so spheres stay inside. (An
    // open mesh's radii also depend on the field across its holes: its centers stay put.)
    StageTimer t(log, "refine");
    const double max_radius = opt.pack.max_radius;
    // Budget mode's first aim is the max: the refinement does not trade it for the total.
    const bool budget = out.limited_by == Limit::budget || out.limited_by == Limit::budget_over_tolerance;
    refine_off_grid(problem.samples[0], problem.weighted[0], out.spheres,
                   [&](const Eigen::Vector3d& c) { return mesh.inside(c) ? std::min(max_radius, mesh.distance(c)) : 0.0; },
                   out.cover.delta, 0.5 * field.shape.voxel_size, log, budget);
  }
  // Largest first (what a host culls by), ties in candidate order.
  std::stable_sort(out.spheres.begin(), out.spheres.end(),
                   [](const Sphere& a, const Sphere& b) { return a.radius > b.radius; });
  return out;
}

}  // namespace spx
