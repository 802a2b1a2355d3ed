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
    problem.spheres.push_back(inscribed_candidates(field, mesh, candidate_options(opt.pack, opt.max_candidates)));
    problem.samples.push_back(surface_samples(mesh.surface(), opt.area_samples, opt.seed));
    problem.weighted.push_back(mesh.surface().vertices.size());
  }
  const SphereSet& candidates = problem.spheres[0];
  if (candidates.empty()) fail_input("", "no inscribed sphere fits: the field holds no interior voxel");
  out.candidates = candidates.size();
  out.pool = candidates;
  out.samples = problem.sample_count();
  {
    StageTimer t(log, "cover");
    out.target = opt.tolerance;
    out.cover = cover_for(problem, out.target, opt.pack.max_spheres, out.limited_by, log);
  }
  for (int c : out.cover.chosen) out.spheres.push_back(candidates[size_t(c)]);
  if (!opt.pack.field_bounds_radius) {
    // Off the voxel grid: the radius stays the exact distance, so spheres stay inside. (An
    // open mesh's radii also depend on the field across its holes: its centers stay put.)
    StageTimer t(log, "refine");
    const double max_radius = opt.pack.max_radius;
    refine_off_grid(problem.samples[0], problem.weighted[0], out.spheres,
                   [&](const Eigen::Vector3d& c) { return mesh.inside(c) ? std::min(max_radius, mesh.distance(c)) : 0.0; },
                   out.cover.delta, 0.5 * field.shape.voxel_size, log);
  }
  // Largest first (what a host culls by), ties in candidate order.
  std::stable_sort(out.spheres.begin(), out.spheres.end(),
                   [](const Sphere& a, const Sphere& b) { return a.radius > b.radius; });
  return out;
}

}  // namespace spx
