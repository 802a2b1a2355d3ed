// Error against sphere count: the cover selection (sphere-pack's default) and the paper's greedy
// packing side by side, on the shared meshes and the car sample, at sphere budgets and at
// tolerances. Each row: median and max vertex-to-union error and overshoot (in % of the mesh's
// bounding-box diagonal), sphere count, lower bound and seconds. Prints JSON (scripts/frontier.sh
// draws the chart).
#include <chrono>
#include <cstdio>

#include "core/atomic_file.hpp"
#include "core/json_io.hpp"
#include "core/version.hpp"
#include "mesh/mesh_query.hpp"
#include "mesh/union_distance.hpp"
#include "pack/cover.hpp"
#include "pack/pack.hpp"
#include "pack/sphere_pack_tool.hpp"
#include "sdf/sdf.hpp"
#include "synthetic/synthetic.hpp"
#include "tool/tool.hpp"

using namespace spx;

namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// How far the union pokes out of the surface: the most any sphere's radius exceeds the exact
// distance from its center to the mesh (or its whole radius, for a center outside).
double overshoot(const MeshQuery& mesh, const SphereSet& spheres) {
  double worst = 0;
  for (const Sphere& s : spheres) {
    if (!(s.radius > 0)) continue;
    const double room = mesh.inside(s.center) ? mesh.distance(s.center) : -mesh.distance(s.center);
    worst = std::max(worst, s.radius - room);
  }
  return worst;
}

json row(const std::string& method, const std::string& mode, double asked, const SphereSet& spheres, const MeshQuery& mesh,
         double seconds, size_t lower_bound) {
  const double diag = mesh.mesh().diagonal();
  const ErrorStats e = vertex_error(mesh.surface(), spheres);
  return {{"method", method},
          {"mode", mode},
          {"asked", asked},
          {"spheres", spheres.size()},
          {"median_pct", 100 * e.median / diag},
          {"max_pct", 100 * e.max / diag},
          {"overshoot_pct", 100 * overshoot(mesh, spheres) / diag},
          {"lower_bound", lower_bound},
          {"seconds", seconds}};
}

// What the cover chose from: candidates by origin and the least delta any cover reaches.
json with_candidates(json row, const CoverSelection& r, double diag) {
  row["candidates"] = r.candidates;
  row["tangent_candidates"] = r.candidates - r.voxel_candidates;
  row["chosen_tangent"] = r.chosen_tangent;
  row["least_reachable_pct"] = 100 * r.cover.least_reachable / diag;
  return row;
}

json bench_mesh(const std::string& name, const TriMesh& mesh, int resolution, const std::vector<size_t>& budgets,
                const std::vector<double>& tolerances, bool tangent, uint64_t seed, Log& log) {
  SdfOptions o;
  o.resolution = resolution;
  const SdfResult sdf = build_sdf(mesh, o);
  const MeshQuery query(mesh);
  const double diag = mesh.diagonal();
  json rows = json::array();
  // The cover exactly as sphere-pack runs it.
  auto cover = [&](size_t budget, double tolerance_pct) {
    SpherePackOptions opt;
    opt.pack.max_spheres = budget;
    opt.pack.field_bounds_radius = sdf.stats.bounded_by_holes;
    opt.tangent_candidates = tangent;
    opt.seed = seed;
    if (tolerance_pct > 0) opt.tolerance = tolerance_pct / 100 * diag;
    return select_by_cover(sdf.field, query, opt);
  };
  PackOptions greedy;
  greedy.field_bounds_radius = sdf.stats.bounded_by_holes;
  for (size_t n : budgets) {
    auto t0 = std::chrono::steady_clock::now();
    const CoverSelection r = cover(n, 0);
    rows.push_back(with_candidates(row("cover", "budget", double(n), r.spheres, query, seconds_since(t0), r.cover.lower_bound), r, diag));
    t0 = std::chrono::steady_clock::now();
    PackOptions g = greedy;
    g.max_spheres = n;
    g.min_radius = sdf.field.shape.voxel_size * 0.5;
    const PackResult packed = pack_spheres(sdf.field, g, &query);
    rows.push_back(row("greedy", "budget", double(n), packed.spheres, query, seconds_since(t0), 0));
    log.progress(name.c_str(), rows.size(), 2 * (budgets.size() + tolerances.size()));
  }
  for (double t : tolerances) {
    const double target = t / 100 * diag;
    auto t0 = std::chrono::steady_clock::now();
    const CoverSelection r = cover(0, t);
    rows.push_back(with_candidates(row("cover", "tolerance", t, r.spheres, query, seconds_since(t0), r.cover.lower_bound), r, diag));
    t0 = std::chrono::steady_clock::now();
    PackOptions g = greedy;
    g.min_radius = sdf.field.shape.voxel_size;
    PackResult packed = pack_spheres(sdf.field, g, &query);
    const ToleranceResult prefix = fewest_spheres_within(mesh, packed.spheres, target);
    packed.spheres.resize(prefix.count);
    json gr = row("greedy", "tolerance", t, packed.spheres, query, seconds_since(t0), 0);
    gr["met"] = prefix.met;
    rows.push_back(gr);
    log.progress(name.c_str(), rows.size(), 2 * (budgets.size() + tolerances.size()));
  }
  return {{"mesh", name}, {"triangles", mesh.triangles.size()}, {"resolution", resolution}, {"rows", rows}};
}

}  // namespace

int main(int argc, char** argv) {
  spx::Tool tool("frontier-bench", "Error against sphere count: cover selection against the greedy packing");
  std::string data = "../shared/data", out;
  int resolution = 128;
  std::vector<size_t> budgets = {16, 32, 64, 128, 256};
  std::vector<double> tolerances = {1, 2, 5};
  std::vector<std::string> only;
  bool voxels_only = false;
  uint64_t seed = SpherePackOptions{}.seed;
  tool.app.add_option("--data", data, "The shared data folder");
  tool.app.add_option("--json", out, "Write the results here")->required();
  tool.app.add_option("--resolution", resolution, "Field cells along the longest side")->capture_default_str();
  tool.app.add_option("--budgets", budgets, "Sphere budgets")->capture_default_str();
  tool.app.add_option("--tolerances", tolerances, "Tolerances in % of the diagonal")->capture_default_str();
  tool.app.add_option("--mesh", only, "Only these meshes (bunny, knight, fertility, elephant, armadillo, car, cube)");
  tool.app.add_option("--seed", seed, "Cover: the surface samples' draw (sphere-pack --seed); the cells' spread over draws")
      ->capture_default_str();
  tool.app.add_flag("--voxel-candidates-only", voxels_only, "The cover without the candidates tangent at the samples");
  return tool.run(argc, argv, [&] {
    struct Case { std::string name, path; };
    const std::vector<Case> cases = {{"bunny", "static/bunny.off"},         {"knight", "static/decimated-knight.off"},
                                     {"fertility", "static/fertility.off"}, {"elephant", "elephant/rest.obj"},
                                     {"cube", "cube/rest.obj"},             {"armadillo", "static/armadillo.obj"},
                                     {"car", ""}};
    json meshes = json::array();
    for (const Case& c : cases) {
      if (!only.empty() && std::find(only.begin(), only.end(), c.name) == only.end()) continue;
      const TriMesh mesh = c.path.empty() ? make_car().rest : load_mesh(data + "/" + c.path).mesh;
      meshes.push_back(bench_mesh(c.name, mesh, resolution, budgets, tolerances, !voxels_only, seed, tool.log));
      tool.log.info(c.name + " done");
    }
    write_json_atomic(out, {{"generator", std::string("frontier-bench (spx) ") + version_string()},
                            {"resolution", resolution},
                            {"seed", seed},
                            {"meshes", meshes}});
  });
}
