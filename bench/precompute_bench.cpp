// precompute-bench: every precompute stage timed on real meshes, side by side with its baseline
// in one run (medians of repeats), as JSON.
//   precompute-bench --data ../shared/data --json OUT.json [--repeats 3] [--max-resolution 512]
//                    [--resolution N ...] [--no-chains] [--no-routes] [--frames [N ...]] [--splits [N ...]]
//                    [--pose-splits [N ...]]
//                    [--sweep-only] [--no-sweep-cache] [--work DIR]
// The routes, the frame sweep and the dense meshes run the tools beside it as whole processes
// (tool_runs.hpp).
#include <openvdb/openvdb.h>
#include <openvdb/tools/MeshToVolume.h>
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <functional>

#include "core/atomic_file.hpp"
#include "core/error.hpp"
#include "core/version.hpp"
#include "tool/tool.hpp"
#include "core/json_io.hpp"
#include "io/spx_writer.hpp"
#include "mesh/mesh_query.hpp"
#include "mesh/winding_number.hpp"
#include "pack/pack.hpp"
#include "posemap/harmonic_map.hpp"
#include "posemap/posemap.hpp"
#include "synthetic/synthetic.hpp"
#include "extract/asset.hpp"
#include "tool_runs.hpp"
#include "sdf/sdf.hpp"

using namespace spx;

namespace {

double peak_rss_gib() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return double(u.ru_maxrss) / (1024.0 * 1024.0);
}

double seconds_of(const std::function<void()>& fn) {
  const auto t0 = std::chrono::steady_clock::now();
  fn();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// Median seconds of `repeats` runs of fn.
double median_seconds(int repeats, const std::function<void()>& fn) {
  std::vector<double> t;
  for (int r = 0; r < repeats; ++r) t.push_back(seconds_of(fn));
  return bench::median(t);
}

openvdb::FloatGrid::Ptr openvdb_filled(const TriMesh& mesh, double h, int band) {
  std::vector<openvdb::Vec3s> points;
  for (const auto& v : mesh.vertices) points.emplace_back(float(v.x() / h), float(v.y() / h), float(v.z() / h));
  std::vector<openvdb::Vec3I> tris;
  for (const auto& f : mesh.triangles) tris.emplace_back(f[0], f[1], f[2]);
  openvdb::tools::QuadAndTriangleDataAdapter<openvdb::Vec3s, openvdb::Vec3I> adapter(points, tris);
  auto xform = openvdb::math::Transform::createLinearTransform(h);
  return openvdb::tools::meshToVolume<openvdb::FloatGrid>(adapter, *xform, float(band),
                                                          std::numeric_limits<float>::max());
}

json sdf_case(const std::string& name, const TriMesh& mesh, int resolution, int repeats, const Log& log) {
  SdfOptions opt;
  opt.resolution = resolution;
  SdfResult ours;
  openvdb::FloatGrid::Ptr base;
  // Side by side, pair by pair: the machine's noise hits both alike, and the least ratio of
  // the pairs is reported beside the ratio of the medians. One untimed pair first: the first
  // run of a process also starts the thread pool and faults in the allocator's first pages.
  std::vector<double> ratios;
  std::vector<double> t_ours_runs, t_base_runs;
  // Each timed run starts from the state the untimed pair left: the run before's result is let
  // go first, so that its memory is there to reuse. (Held while the next one was built, the first
  // timed field took fresh pages, the kernel zeroing each: that run alone was 15 % slower.)
  ours = build_sdf(mesh, opt);
  const double h = ours.field.shape.voxel_size;
  base = openvdb_filled(mesh, h, opt.band);
  for (int r = 0; r < repeats; ++r) {
    ours = SdfResult();
    t_ours_runs.push_back(seconds_of([&] { ours = build_sdf(mesh, opt); }));
    base.reset();
    t_base_runs.push_back(seconds_of([&] { base = openvdb_filled(mesh, h, opt.band); }));
    ratios.push_back(t_base_runs.back() / t_ours_runs.back());
  }
  const double t_ours = bench::median(t_ours_runs), t_base = bench::median(t_base_runs);
  const double least_ratio = *std::min_element(ratios.begin(), ratios.end());
  // Accuracy against the baseline over the interior: sign agreement and distance difference.
  auto acc = base->getConstAccessor();
  const GridShape& g = ours.field.shape;
  size_t interior = 0, sign_differs = 0;
  double max_diff = 0;
  for (size_t idx = 0; idx < g.count(); ++idx) {
    const Eigen::Vector3i c = g.coords(idx) + g.origin;
    const float b = acc.getValue(openvdb::Coord(c.x(), c.y(), c.z()));
    const float o = ours.field.values[idx];
    if (o >= 0 && b >= 0) continue;
    ++interior;
    if ((o < 0) != (b < 0)) {
      ++sign_differs;
      continue;
    }
    max_diff = std::max(max_diff, double(std::abs(o - b)) / h);
  }
  // Both against the truth on a sample of the interior (every voxel either calls inside):
  // the exact distance (CGAL) with the winding number's side.
  const MeshQuery query(mesh);
  const WindingNumber wn(mesh);
  const size_t stride = std::max<size_t>(1, interior / 20000);
  size_t seen = 0, sampled = 0, ours_sign = 0, base_sign = 0;
  double ours_max = 0, base_max = 0, ours_sum = 0, base_sum = 0;
  for (size_t idx = 0; idx < g.count(); ++idx) {
    const Eigen::Vector3i c = g.coords(idx) + g.origin;
    const float b = acc.getValue(openvdb::Coord(c.x(), c.y(), c.z()));
    const float o = ours.field.values[idx];
    if ((o >= 0 && b >= 0) || seen++ % stride != 0) continue;
    const Eigen::Vector3d p = g.world(idx);
    const bool in = wn.inside(p);
    const double truth = in ? -query.distance(p) : query.distance(p);
    ++sampled;
    ours_sign += (o < 0) != in;
    base_sign += (b < 0) != in;
    const double eo = std::abs(o - truth) / h, eb = std::abs(b - truth) / h;
    ours_max = std::max(ours_max, eo);
    base_max = std::max(base_max, eb);
    ours_sum += eo;
    base_sum += eb;
  }
  // Every voxel within a voxel of the surface, where a sign is hardest: ours against the winding number.
  size_t near_surface = 0, near_sign_errors = 0;
  for (size_t idx = 0; idx < g.count(); ++idx) {
    const float o = ours.field.values[idx];
    if (std::abs(o) > h) continue;
    ++near_surface;
    near_sign_errors += (o < 0) != wn.inside(g.world(idx));
  }
  bench::say(log, "%s @%d: %zu sign errors among the %zu voxels within a voxel of the surface", name.c_str(),
             resolution, near_sign_errors, near_surface);
  const json truth = {{"near_surface_voxels", near_surface},
                      {"near_surface_sign_errors", near_sign_errors},
                      {"sampled_voxels", sampled},
                      {"ours_max_error_voxels", ours_max},
                      {"ours_mean_error_voxels", ours_sum / double(std::max<size_t>(sampled, 1))},
                      {"ours_sign_errors", ours_sign},
                      {"openvdb_max_error_voxels", base_max},
                      {"openvdb_mean_error_voxels", base_sum / double(std::max<size_t>(sampled, 1))},
                      {"openvdb_sign_errors", base_sign}};
  SphereSet spheres;
  const double t_pack = median_seconds(repeats, [&] { spheres = pack_spheres(ours.field, {}, &query).spheres; });
  bench::say(log,
             "%s @%d: ours %.3f s, OpenVDB filled %.3f s (%.2fx), pack %.3f s (%zu spheres); against the exact "
             "distance (%zu voxels): ours max %.3f / mean %.4f voxels, %zu sign errors; OpenVDB max %.3f / mean %.4f, "
             "%zu sign errors",
             name.c_str(), resolution, t_ours, t_base, t_base / t_ours, t_pack, spheres.size(), sampled, ours_max,
             ours_sum / double(std::max<size_t>(sampled, 1)), ours_sign, base_max,
             base_sum / double(std::max<size_t>(sampled, 1)), base_sign);
  return {{"mesh", name},
          {"triangles", mesh.triangles.size()},
          {"resolution", resolution},
          {"voxels", g.count()},
          {"interior_voxels", ours.stats.interior_voxels},
          {"sdf_s", t_ours},
          {"openvdb_filled_s", t_base},
          {"speedup_vs_openvdb", t_base / t_ours},
          {"least_pair_speedup", least_ratio},
          {"sdf_runs_s", t_ours_runs},
          {"openvdb_filled_runs_s", t_base_runs},
          {"max_interior_difference_voxels", max_diff},
          {"sign_differs_voxels", sign_differs},
          {"interior_compared_voxels", interior},
          {"against_exact", truth},
          {"pack_s", t_pack},
          {"spheres", spheres.size()},
          {"peak_rss_gib", peak_rss_gib()}};
}

json chain_case(const std::string& name, const TriMesh& rest, const std::vector<TriMesh>& poses, int repeats,
                const Log& log) {
  json stages;
  SdfOptions opt;
  SdfResult sdf;
  stages["sdf_s"] = median_seconds(repeats, [&] { sdf = build_sdf(rest, opt); });
  const MeshQuery query(rest);
  SpheresFile spheres;
  spheres.voxel_size = sdf.field.shape.voxel_size;
  stages["pack_s"] = median_seconds(repeats, [&] { spheres.spheres = pack_spheres(sdf.field, {}, &query).spheres; });
  TetMesh tets;
  stages["tetrahedralize_s"] = median_seconds(repeats, [&] { tets = tetrahedralize(rest, {}); });
  std::unique_ptr<HarmonicMap> f;
  stages["harmonic_setup_s"] = median_seconds(repeats, [&] { f = std::make_unique<HarmonicMap>(tets, rest); });
  stages["interior_map_per_pose_s"] =
      median_seconds(repeats, [&] { for (const auto& p : poses) f->deform(p); }) / double(poses.size());
  std::vector<PoseInput> inputs;
  for (size_t i = 0; i < poses.size(); ++i) inputs.push_back({"p" + std::to_string(i), "", poses[i]});
  PoseMapResult mapped;
  stages["pose_map_total_s"] = median_seconds(repeats, [&] { mapped = pose_map(rest, "rest", inputs, spheres, {}); });
  stages["radii_and_sites_s"] = std::max(0.0, stages["pose_map_total_s"].get<double>() -
                                                  stages["tetrahedralize_s"].get<double>() -
                                                  stages["harmonic_setup_s"].get<double>() -
                                                  stages["interior_map_per_pose_s"].get<double>() * double(poses.size()));
  stages["export_spx_s"] = median_seconds(repeats, [&] { encode_spx(mapped.proxy); });
  double total = 0;
  for (const char* k : {"sdf_s", "pack_s", "pose_map_total_s", "export_spx_s"}) total += stages[k].get<double>();
  stages["chain_total_s"] = total;
  bench::say(log, "%s chain: %.2f s (sdf %.2f, pack %.2f, pose-map %.2f of which tets %.2f)", name.c_str(), total,
             stages["sdf_s"].get<double>(), stages["pack_s"].get<double>(), stages["pose_map_total_s"].get<double>(),
             stages["tetrahedralize_s"].get<double>());
  return {{"mesh", name},        {"triangles", rest.triangles.size()}, {"poses", poses.size()},
          {"spheres", spheres.spheres.size()}, {"tets", tets.tets.size()}, {"stages", stages},
          {"peak_rss_gib", peak_rss_gib()}};
}

struct Plan {
  std::string data = "../shared/data", out, work;
  int repeats = 3, max_res = 512;
  std::vector<int> resolutions = {64, 128, 256, 512};
  std::vector<size_t> frames = {4, 8, 16, 32, 48, 100};
  std::vector<int> splits = {1, 2};  // the armadillo split at its midpoints this many times
  std::vector<int> pose_splits = {3};  // the elephant's poses and its walk's frames split so, for pose-map
  bool chains = true, routes = true, batch = true, sweep_only = false, sweep_cached = true;
};

void run(const Plan& plan, const Log& log);

}  // namespace

int main(int argc, char** argv) {
  spx::Tool tool("precompute-bench", "Precompute benchmark: every stage, with OpenVDB's filled SDF as the baseline");
  CLI::App& app = tool.app;
  Plan plan;
  plan.work = (std::filesystem::temp_directory_path() / "spx-precompute-bench").string();
  app.add_option("--data", plan.data, "The shared data folder");
  app.add_option("--json", plan.out, "Write the results here")->required();
  app.add_option("--repeats", plan.repeats, "Runs per measurement (the median is reported)");
  app.add_option("--max-resolution", plan.max_res, "Largest armadillo resolution");
  app.add_option("--resolution", plan.resolutions, "Armadillo resolutions (default 64 128 256 512)");
  app.add_flag("!--no-chains", plan.chains, "Only the SDF cases");
  app.add_flag("!--no-routes", plan.routes, "Without the tools' routes, the frame sweep and the dense meshes");
  CLI::Option* frames =
      app.add_option("--frames", plan.frames, "Frame counts of the sweep (default 4 8 16 32 48 100; none: skip it)")
          ->expected(0, CLI::detail::expected_max_vector_size);
  // How many times a dense case's meshes are split at their midpoints (none: skip them).
  auto split_counts = [&](const char* name, std::vector<int>& counts, const std::string& what, const char* given) {
    return app.add_option(name, counts, what + " split at their midpoints N times, spaced against --every-vertex "
                                        "(default " + given + "; none: skip it)")
        ->expected(0, CLI::detail::expected_max_vector_size)
        ->check(CLI::Range(0, 3));
  };
  CLI::Option* splits = split_counts("--splits", plan.splits, "sphere-pack on the armadillo", "1 2");
  CLI::Option* pose_splits = split_counts("--pose-splits", plan.pose_splits,
                                                "pose-map on the elephant and its 4 poses, and on 4 frames of its rigged walk", "3");
  app.add_flag("!--no-batch", plan.batch, "Without the batch (the routes' meshes twice each, two chains at a time)");
  app.add_flag("--sweep-only", plan.sweep_only, "Only the frame sweep (no routes, SDF cases or chains)");
  app.add_flag("!--no-sweep-cache", plan.sweep_cached,
               "The frame sweep without its runs from a --cache written before (the routes keep theirs)");
  app.add_option("--work", plan.work, "Where the routes and the sweep write their files");
  return tool.run(argc, argv, [&] {
    // `--frames` alone reaches CLI11 as one empty value, which it reads as 0.
    if (frames->results() == std::vector<std::string>{""}) plan.frames.clear();
    if (splits->results() == std::vector<std::string>{""}) plan.splits.clear();
    if (pose_splits->results() == std::vector<std::string>{""}) plan.pose_splits.clear();
    for (size_t n : plan.frames)
      if (n == 0) fail_usage("--frames", "a frame count must be at least 1");
    run(plan, tool.log);
  });
}

namespace {

// The routes' two bodies: the elephant and its 4 poses, and the car sample (generated).
std::vector<bench::RouteBody> route_bodies(const Plan& plan, const std::string& tools) {
  bench::RouteBody elephant{"elephant", plan.data + "/elephant/rest.obj", {}};
  for (const char* p : {"pose-050", "pose-150", "pose-300", "pose-456"})
    elephant.poses.push_back(plan.data + "/elephant/" + p + ".obj");
  bench::run_tool(tools, {"sample-gen", "car", "-o", plan.work + "/car-in", "-q"});
  bench::RouteBody car{"car", plan.work + "/car-in/rest.obj", {}};
  for (const std::string& name : make_car().pose_names) car.poses.push_back(plan.work + "/car-in/" + name + ".obj");
  return {elephant, car};
}

// The default route against the paper's on each body.
json route_cases(const Plan& plan, const std::vector<bench::RouteBody>& bodies, const std::string& tools,
                 const Log& log) {
  json routes = json::array();
  for (const bench::RouteBody& body : bodies)
    routes.push_back(bench::route_case(tools, body.name, body.rest, body.poses, plan.work, plan.repeats, log));
  return routes;
}

// pose-map over more and more frames of two clips: the elephant's walk (--select N) and
// RiggedSimple's 2 s clip sampled evenly (--times).
json frame_sweeps(const Plan& plan, const std::string& tools, const Log& log) {
  json sweeps = json::array();
  if (plan.frames.empty()) return sweeps;
  const bench::ClipSweep walk{"elephant-walk", plan.data + "/elephant/elephant-rigged.glb", {"--animation", "0"},
                              [](size_t n) { return std::vector<std::string>{"--select", std::to_string(n)}; }};
  const std::string simple = plan.data + "/rigged-simple/RiggedSimple.glb";
  const double end = Asset(simple, "").clips().at(0).end;
  const bench::ClipSweep bend{"RiggedSimple", simple, {"--animation", "0"}, [end](size_t n) {
                                std::string times;
                                for (size_t k = 0; k < n; ++k)
                                  times += (k ? "," : "") + std::to_string(n > 1 ? 0.999 * end * double(k) / double(n - 1) : 0.0);
                                return std::vector<std::string>{"--times", times};
                              }};
  for (const bench::ClipSweep& clip : {walk, bend})
    sweeps.push_back(bench::frame_sweep(tools, clip, plan.frames, plan.work, plan.repeats, plan.sweep_cached, log));
  return sweeps;
}

// sphere-pack on the armadillo split to a scan's density: the cover on spaced vertices (the
// default) against every vertex's, at the default tolerance and at 64 spheres.
json dense_cases(const Plan& plan, const std::string& tools, const Log& log) {
  json cases = json::array();
  for (int split : plan.splits)
    cases.push_back(
        bench::dense_case(tools, "armadillo", plan.data + "/static/armadillo.obj", split, 64, plan.work, plan.repeats, log));
  return cases;
}

json dense_pose_cases(const Plan& plan, const std::string& tools, const Log& log) {
  json cases = json::array();
  std::vector<std::string> poses;
  for (const char* p : {"pose-050", "pose-150", "pose-300", "pose-456"}) poses.push_back(plan.data + "/elephant/" + p + ".obj");
  for (int split : plan.pose_splits) {
    cases.push_back(bench::dense_poses_case(tools, "elephant", plan.data + "/elephant/rest.obj", poses, split, plan.work,
                                            plan.repeats, log));
    cases.push_back(bench::dense_skinned_case(tools, "elephant-walk", plan.data + "/elephant/elephant-rigged.glb",
                                              {"--animation", "0", "--select", "4"}, split, plan.work, plan.repeats, log));
  }
  return cases;
}

void run(const Plan& plan, const Log& log) {
  openvdb::initialize();
  const std::string& data = plan.data;
  const int repeats = plan.repeats;
  json result = {{"generator", std::string("precompute-bench (spx) ") + spx::version_string()}, {"repeats", repeats}};
  // The tools first: a child's peak memory (ru_maxrss) starts from this process's own at the
  // spawn, which the in-process cases below raise.
  if (plan.routes || plan.sweep_only) {
    const std::string tools = bench::tools_dir_beside_this_program();
    if (!plan.sweep_only) {
      const std::vector<bench::RouteBody> bodies = route_bodies(plan, tools);
      result["routes"] = route_cases(plan, bodies, tools, log);
      // A farm's batch: each body twice, in turn (elephant, car, elephant, car).
      if (plan.batch)
        result["batch"] = bench::batch_case(tools, {bodies[0], bodies[1], bodies[0], bodies[1]}, plan.work, plan.repeats, log);
    }
    result["frame_sweeps"] = frame_sweeps(plan, tools, log);
    if (!plan.sweep_only) result["dense"] = dense_cases(plan, tools, log);
    if (!plan.sweep_only) result["dense_poses"] = dense_pose_cases(plan, tools, log);
  }
  if (plan.sweep_only) {
    write_json_atomic(plan.out, result);
    return;
  }
  const TriMesh armadillo = load_mesh(data + "/static/armadillo.obj").mesh;
  json sdf = json::array();
  for (int res : plan.resolutions)
    if (res <= plan.max_res) sdf.push_back(sdf_case("armadillo", armadillo, res, res >= 512 ? 1 : repeats, log));
  result["sdf"] = sdf;
  json chains = json::array();
  if (plan.chains) {
    const LoadedMesh rest = load_mesh(data + "/elephant/rest.obj");
    std::vector<TriMesh> poses;
    for (const char* p : {"pose-050", "pose-150", "pose-300", "pose-456"})
      poses.push_back(load_pose(data + "/elephant/" + p + ".obj", rest));
    chains.push_back(chain_case("elephant", rest.mesh, poses, repeats, log));
    const SampleAsset car = make_car();
    std::vector<TriMesh> car_poses;
    for (size_t i = 0; i < car.pose_names.size(); ++i) car_poses.push_back(car.pose(i));
    chains.push_back(chain_case("car", car.rest, car_poses, repeats, log));
  }
  result["chains"] = chains;
  write_json_atomic(plan.out, result);
}

}  // namespace
