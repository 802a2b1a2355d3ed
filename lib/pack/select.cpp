#include "pack/select.hpp"

#include <algorithm>
#include <functional>
#include <optional>
#include <numeric>
#include <tuple>

#include "core/error.hpp"
#include "core/format.hpp"
#include "mesh/union_distance.hpp"
#include "pack/candidate_cache.hpp"
#include "pack/median_descent.hpp"

namespace spx {
namespace {

// Budget mode, `rounds` times: the budget covered again from every candidate and every set
// refined so far (the last one a cover at its largest gap, where the bisection starts), then
// refined; the best set (kept_over) is kept, its cover with it. A refined sphere sits where no
// voxel or sample offered one, so the cover can pair it with others it could not before, and
// the refinement descends again from another start.
// (Spaced, the covers are over `problem`'s samples and the errors over `every` sample.)
void polish(const CoverProblem& problem, const CoverProblem& every, size_t budget, CoverSelection& out,
            const std::function<double(const Eigen::Vector3d&)>& radius_at, double step, int rounds, Log& log) {
  CoverProblem again = problem;
  again.spheres = {out.offered};
  SphereSet current = out.spheres;
  const std::vector<Eigen::Vector3d>& samples = every.samples[0];
  const size_t weighted = every.weighted[0];
  UnionGaps now = union_gaps(samples, weighted, current), best = now;
  for (int round = 1; round <= rounds; ++round) {
    again.spheres[0].insert(again.spheres[0].end(), current.begin(), current.end());
    CoverResult cover = cover_with_budget(again, budget, kRefinedBudgetSlack, 1e-2, log, now.largest);
    current.clear();
    for (int c : cover.chosen) current.push_back(again.spheres[0][size_t(c)]);
    refine_off_grid(samples, weighted, current, radius_at, cover.delta, step, log, true);
    now = union_gaps(samples, weighted, current);
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

// Tolerance mode: how many times the spaced cover is made every vertex's (cover_every_vertex).
constexpr int kSpacedPasses = 2;
// Budget mode spaces the vertices only where they outnumber the area samples this many times
// (its spacing asks a cover of the area samples first).
constexpr size_t kVerticesPerAreaSample = 8;

std::vector<uint32_t> every_index(size_t n) {
  std::vector<uint32_t> out(n);
  std::iota(out.begin(), out.end(), 0u);
  return out;
}

// The problem's samples: the `working` ones of `samples` (vertices first, ascending, then the
// area samples), the vertices weighted.
void set_working_samples(const SurfaceSamples& samples, size_t vertices, const std::vector<uint32_t>& working,
                         CoverProblem& problem) {
  problem.samples.assign(1, {});
  for (uint32_t i : working) problem.samples[0].push_back(samples.points[i]);
  problem.weighted.assign(1, size_t(std::lower_bound(working.begin(), working.end(), uint32_t(vertices)) - working.begin()));
}

// The vertices left out of `working` that `chosen` leaves farther than `delta`: the spaced
// cover's promise is every vertex's, so these join the problem and the cover is solved again.
std::vector<uint32_t> vertices_left_bare(const SurfaceSamples& samples, size_t vertices, const std::vector<uint32_t>& working,
                                         const CoverProblem& problem, const std::vector<int>& chosen, double delta) {
  SphereSet spheres;
  for (int c : chosen) spheres.push_back(problem.spheres[0][size_t(c)]);
  const std::vector<double> gap =
      union_signed_distance({samples.points.begin(), samples.points.begin() + long(vertices)}, spheres);
  std::vector<char> in_working(vertices, 0);
  for (uint32_t i : working)
    if (i < vertices) in_working[i] = 1;
  std::vector<uint32_t> bare;
  for (size_t i = 0; i < vertices; ++i)
    if (!in_working[i] && gap[i] > delta) bare.push_back(uint32_t(i));
  return bare;
}

// The vertices `bare` join the samples the cover is solved on, with their own candidates.
void join_working(const SurfaceSamples& samples, size_t vertices, const std::vector<uint32_t>& bare,
                  const std::function<void(const std::vector<uint32_t>&)>& add_candidates,
                  std::vector<uint32_t>& working, CoverProblem& problem, CoverSelection& out) {
  out.spaced_joined += bare.size();
  add_candidates(bare);
  working.insert(working.end(), bare.begin(), bare.end());
  std::sort(working.begin(), working.end());
  set_working_samples(samples, vertices, working, problem);
}

// The spaced cover (select_by_cover) made every vertex's: each vertex it leaves farther than the
// tolerance joins the samples with its own candidates (`add_candidates`) and the cover is
// completed by a short search from the last, until none is left bare. Each short search stays
// near the first cover, so the whole is done twice, the second from a full search over the samples
// the first learned; the smaller cover is kept.
void cover_every_vertex(const SurfaceSamples& samples, size_t vertices,
                        const std::function<void(const std::vector<uint32_t>&)>& add_candidates,
                        std::vector<uint32_t>& working, CoverProblem& problem, CoverSelection& out, Log& log) {
  const double tolerance = out.target;
  std::optional<CoverResult> best;
  for (int pass = 0; pass < kSpacedPasses; ++pass) {
    if (pass > 0) out.cover = cover_within(problem, tolerance, kToleranceSearch, log);
    for (;;) {
      const std::vector<uint32_t> bare = vertices_left_bare(samples, vertices, working, problem, out.cover.chosen, tolerance);
      log.detail("cover on " + std::to_string(problem.weighted[0]) + " of " + std::to_string(vertices) +
                 " vertices: " + std::to_string(out.cover.chosen.size()) + " spheres, " + std::to_string(bare.size()) +
                 " more vertices past the tolerance");
      if (bare.empty()) break;
      join_working(samples, vertices, bare, add_candidates, working, problem, out);
      out.cover = cover_within(problem, tolerance, kWarmSearch, log, out.cover.chosen);
    }
    if (!best || out.cover.chosen.size() < best->chosen.size()) best = out.cover;
  }
  out.cover = std::move(*best);
  out.limited_by = out.cover.uncoverable() > 0 ? Limit::resolution : Limit::tolerance;
  log.info("covered on " + std::to_string(problem.weighted[0]) + " of the " + std::to_string(vertices) +
           " vertices (those an eighth of the tolerance apart, and " + std::to_string(out.spaced_joined) +
           " a cover left past it), then every vertex checked");
}

// The chosen spheres moved off the voxel grid, the radius staying the exact distance so that
// they stay inside (an open mesh's radii also depend on the field across its holes: its centres
// stay put, and this is not called); budget mode then polishes them.
void refine_selected(const DenseField& field, const MeshQuery& mesh, const SpherePackOptions& opt,
                     const CoverProblem& problem, const CoverProblem& every, CoverSelection& out, Log& log) {
  StageTimer t(log, "refine");
  const double max_radius = opt.pack.max_radius, min_radius = opt.pack.min_radius;
  // Budget mode's first aim is the max: the refinement does not trade it for the total.
  const bool budget = out.limited_by == Limit::budget || out.limited_by == Limit::budget_over_tolerance;
  // No move to where the sphere would be smaller than --min-radius (0: not given) allows.
  const auto radius_at = [&](const Eigen::Vector3d& c) {
    const double r = mesh.inside(c) ? std::min(max_radius, mesh.distance(c)) : 0.0;
    return r >= min_radius ? r : 0.0;
  };
  const double step = 0.5 * field.shape.voxel_size;
  refine_off_grid(every.samples[0], every.weighted[0], out.spheres, radius_at, out.cover.delta, step, log, budget);
  if (budget) polish(problem, every, opt.pack.max_spheres, out, radius_at, step, opt.polish_rounds, log);
}

// Budget mode on spaced vertices: the vertices the cover leaves past its delta join, with their
// own candidates, and the budget is covered once more from that delta (each budget cover is a
// bisection over tables, so once, as pose-map's budget mode checks its other frames once); the
// refinement, over every vertex, takes on what that cover leaves.
void join_bare_vertices_once(const SurfaceSamples& samples, size_t vertices,
                             const std::function<void(const std::vector<uint32_t>&)>& add_candidates,
                             std::vector<uint32_t>& working, CoverProblem& problem, CoverSelection& out, size_t budget,
                             double slack, Log& log) {
  const std::vector<uint32_t> bare = vertices_left_bare(samples, vertices, working, problem, out.cover.chosen, out.cover.delta);
  log.info("covered on " + std::to_string(problem.weighted[0]) + " of the " + std::to_string(vertices) +
           " vertices (those an eighth of the area samples' delta apart); " + std::to_string(bare.size()) +
           " others past the cover's delta join");
  if (bare.empty()) return;
  join_working(samples, vertices, bare, add_candidates, working, problem, out);
  out.cover = cover_with_budget(problem, budget, slack, 1e-2, log, out.cover.delta);
}

// Budget mode on a mesh of many more vertices than area samples: the delta the budget reaches
// over the area samples alone, each with its own candidate besides the field's. It stands for
// the budget's delta over every sample, which sets how far apart the vertices can be spaced.
double area_samples_delta(const SurfaceSamples& samples, size_t vertices, const SphereSet& voxel_candidates,
                          const std::function<TangentCandidates(const std::vector<uint32_t>&)>& tangent, size_t budget) {
  std::vector<uint32_t> area(samples.points.size() - vertices);
  std::iota(area.begin(), area.end(), uint32_t(vertices));
  CoverProblem p;
  p.spheres = {voxel_candidates};
  const TangentCandidates t = tangent(area);
  p.spheres[0].insert(p.spheres[0].end(), t.spheres.begin(), t.spheres.end());
  p.merge = kCandidateMerge;
  set_working_samples(samples, vertices, area, p);
  p.weighted = {area.size()};
  return cover_with_budget(p, budget, 0).least_max_delta;
}

// How far apart the vertices a cover is first solved on may lie (0: every vertex): an eighth of
// the tolerance, or in budget mode of the area samples' delta where the vertices outnumber them
// kVerticesPerAreaSample times. (With both a tolerance and a budget, every vertex.)
double vertex_spacing(const MeshQuery& mesh, const SpherePackOptions& opt, const SurfaceSamples& samples,
                      const SphereSet& voxel_candidates,
                      const std::function<TangentCandidates(const std::vector<uint32_t>&)>& tangent) {
  const size_t vertices = mesh.surface().vertices.size(), budget = opt.pack.max_spheres;
  if (!opt.spaced_vertices || !opt.tangent_candidates) return 0;
  if (budget == 0) return kCoverSpacing * opt.tolerance;
  if (opt.tolerance > 0 || opt.area_samples == 0 || vertices <= kVerticesPerAreaSample * opt.area_samples) return 0;
  return kCoverSpacing * area_samples_delta(samples, vertices, voxel_candidates, tangent, budget);
}

// No candidate at all, said as greedy packing says it: the deepest voxel against the least radius.
[[noreturn]] void fail_no_candidates(const DenseField& field, double min_radius) {
  double deepest = 0;
  for (float v : field.values) deepest = std::max(deepest, -double(v));
  if (!(deepest > 0)) fail_input("", "no inscribed sphere fits: the field holds no interior voxel");
  fail_input("", "no inscribed sphere fits: the largest interior distance, " + num(deepest) + ", is " +
                     (deepest < min_radius ? "below" : "near") + " the min radius " + num(min_radius));
}
// The samples `which`'s own candidates (tangent_candidates), their balls kept in `cache`.
TangentCandidates cached_tangent_candidates(CandidateCache& cache, const DenseField& field, const MeshQuery& mesh,
                                            const SurfaceSamples& samples, const CandidateOptions& limits,
                                            const std::vector<uint32_t>& which) {
  const std::vector<SampleBalls> balls = cache.tangent_balls(which, [&](const std::vector<uint32_t>& missing) {
    return tangent_balls(mesh, mesh.surface(), samples, missing, &field, deepest_radius(field), limits);
  });
  return tangent_candidates_of(balls, which, samples, mesh.surface());
}

// What the kept cover chose from (the field's voxels, the samples' tangent balls, or, polished,
// an earlier refinement's spheres), and its spheres largest first (what a host culls by), ties
// in candidate order.
void order_chosen(CoverSelection& out) {
  for (int c : out.cover.chosen) {
    out.chosen_tangent += size_t(c) >= out.voxel_candidates && size_t(c) < out.offered.size();
    out.chosen_refined += size_t(c) >= out.offered.size();
  }
  std::stable_sort(out.spheres.begin(), out.spheres.end(),
                   [](const Sphere& a, const Sphere& b) { return a.radius > b.radius; });
}

// The cache's file written where this run added to it (a file that cannot be written is a
// warning: the spheres do not need it), and what it gave in the report.
// Then the folder kept under its limit.
void save_cache(const CandidateCache& cache, const SpherePackOptions& opt, CoverSelection& out, Log& log) {
  if (!cache.active()) return;
  out.cache = {cache.file(), cache.voxels_read(), cache.balls_read(), cache.balls_made(), {}};
  const std::string failed = cache.save();
  if (!failed.empty()) log.warn(failed + ": the candidates are not cached");
  out.cache->folder = keep_cache_under(opt.cache_dir, opt.cache_limit, {cache.file()}, log);
}
}  // namespace

// Selection by coverage: inscribed candidates, samples on the surface, a set cover for the
// tolerance or the budget, then the centers refined off the grid.
CoverSelection select_by_cover(const DenseField& field, const MeshQuery& mesh, const SpherePackOptions& opt, Log& log) {
  if (!(opt.tolerance > 0) && opt.pack.max_spheres == 0)
    fail_option("tolerance", "give a tolerance (a length) or a sphere budget: the cover method needs one");
  CoverSelection out;
  CoverProblem problem;
  SurfaceSamples samples;
  const size_t vertices = mesh.surface().vertices.size();
  // The samples the cover is solved on: every one, or (spaced) the vertices kCoverSpacing x the
  // tolerance apart and every area sample, joined by the vertices that cover leaves bare.
  std::vector<uint32_t> working;
  const size_t budget = opt.pack.max_spheres;
  const CandidateOptions limits = candidate_options(opt.pack);
  samples = sample_surface(mesh.surface(), opt.area_samples, opt.seed);
  CandidateCache cache;
  if (!opt.cache_dir.empty()) cache = CandidateCache(opt.cache_dir, field, mesh.surface(), samples, limits);
  // The samples' own candidates (tangent_candidates), their balls kept in the cache.
  const auto tangent = [&](const std::vector<uint32_t>& which) {
    return cached_tangent_candidates(cache, field, mesh, samples, limits, which);
  };
  const auto add_tangent_candidates = [&](const std::vector<uint32_t>& which) {
    const TangentCandidates t = tangent(which);
    problem.spheres[0].insert(problem.spheres[0].end(), t.spheres.begin(), t.spheres.end());
    out.touching_samples += t.touching;
    out.unreached_samples += t.unreached;
  };
  {
    StageTimer t(log, "candidates");
    problem.spheres.push_back(cache.voxel_candidates([&] { return inscribed_candidates(field, mesh, limits); }));
    out.voxel_candidates = problem.spheres[0].size();
    working = samples_to_cover(samples.points, vertices, vertex_spacing(mesh, opt, samples, problem.spheres[0], tangent),
                               out.vertex_spacing);
    if (opt.tangent_candidates) {
      add_tangent_candidates(working);
      problem.merge = kCandidateMerge;
    }
    set_working_samples(samples, vertices, working, problem);
  }
  const SphereSet& candidates = problem.spheres[0];
  if (candidates.empty()) fail_no_candidates(field, opt.pack.min_radius);
  out.samples = samples.points.size();
  const bool spaced = out.vertex_spacing > 0;
  // The centres are refined off the grid after the cover (below), unless the field bounds the radii.
  const bool refined = !opt.pack.field_bounds_radius;
  {
    StageTimer t(log, "cover");
    out.target = opt.tolerance;
    const double slack = refined ? kRefinedBudgetSlack : kBudgetSlack;
    out.cover = cover_for(problem, out.target, opt.pack.max_spheres, out.limited_by, log, slack);
    if (spaced && budget == 0) cover_every_vertex(samples, vertices, add_tangent_candidates, working, problem, out, log);
    if (spaced && budget > 0)
      join_bare_vertices_once(samples, vertices, add_tangent_candidates, working, problem, out, budget, slack, log);
    if (out.limited_by == Limit::resolution)
      out.out_of_reach_added = cover_out_of_reach(problem, out.cover.uncovered, out.cover.chosen);
    out.candidates = candidates.size();
    out.cover_samples = problem.sample_count();
  }
  // The refinement weighs every sample, not only the cover's.
  CoverProblem every;
  if (spaced) set_working_samples(samples, vertices, every_index(samples.points.size()), every);
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
  if (refined) refine_selected(field, mesh, opt, problem, spaced ? every : problem, out, log);
  order_chosen(out);
  note_unused_budget(out.limited_by, out.spheres.size(), opt.pack.max_spheres, log);
  save_cache(cache, opt, out, log);
  return out;
}

}  // namespace spx
