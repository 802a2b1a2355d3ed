// crash-bench: the paper's Table 1 in our own Bullet host. Every configuration runs the same
// 8-car ramp scene side by side in one process:
//   compound-N     the proxy as a btCompoundShape of btSphereShape (the paper's setup)
//   sphereset-N    the same spheres as an spx::bullet sphere set: its algorithms against the ground,
//                  the ramps and the other cars
//   triangle-mesh  the car mesh in a btGImpactMeshShape (the paper's baseline)
// The crash is chaotic (a different contact model gives a different pile-up), so every
// configuration runs several seeds (each its own crash); a run's time is the mean over seeds,
// and the reported time the median over interleaved repeats. Monitored runs (never timed)
// measure error over time, contacts, tunnelling, penetration and energy; a stability sweep
// repeats them at larger steps and higher launch speeds.
//   crash-bench --rest rest.obj --pose front.obj ... --proxy car-320.spx --proxy car-66.spx
//               --json OUT.json [--repeats 5] [--seeds 3] [--seconds 10] [--no-stability]
//               [--profile NAME]
#include <algorithm>
#include <cstdio>

#include "core/error.hpp"
#include "core/format.hpp"
#include "core/version.hpp"
#include "tool/tool.hpp"
#include "crash_host.hpp"
#include "mesh/mesh.hpp"

using namespace spx;
using namespace spx::crash;

namespace {

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0 : v[v.size() / 2];
}

json error_json(const RunStats& run) {
  std::vector<double> medians, maxima;
  json cars = json::array();
  for (const auto& trace : run.error) {
    medians.insert(medians.end(), trace.median.begin(), trace.median.end());
    maxima.insert(maxima.end(), trace.max.begin(), trace.max.end());
    cars.push_back({{"median", trace.median}, {"max", trace.max}});
  }
  return {{"median_of_medians_m", median(medians)},
          {"max_m", maxima.empty() ? 0.0 : *std::max_element(maxima.begin(), maxima.end())},
          {"times_s", run.sample_times},
          {"cars", cars}};
}

// Summed over the crashes of several seeds (tunnels), or their worst (penetration, energy).
json safety_json(const std::vector<RunStats>& runs) {
  int ground = 0, cars = 0;
  double contact = 0, below = 0, energy = 0;
  bool blew_up = false;
  for (const auto& run : runs) {
    ground += run.ground_tunnels;
    cars += run.car_tunnels;
    contact = std::max(contact, run.max_contact_penetration);
    below = std::max(below, run.max_ground_penetration);
    energy = std::max(energy, run.max_energy_ratio);
    blew_up = blew_up || run.energy_blew_up();
  }
  return {{"ground_tunnels", ground},
          {"car_tunnels", cars},
          {"max_contact_penetration_m", contact},
          {"max_ground_penetration_m", below},
          {"max_energy_ratio", energy},
          {"energy_blew_up", blew_up},
          {"crashes", runs.size()}};
}

// One timed run: the mean over `seeds` crashes (the first crash's stats, mean timings).
RunStats run_seeds(const CarAsset& asset, SceneOptions scene, int seeds) {
  RunStats first;
  double sim = 0, deform = 0;
  for (int k = 0; k < seeds; ++k) {
    const RunStats run = run_scene(asset, scene);
    if (k == 0) first = run;
    sim += run.sim_ms;
    deform += run.deform_ms;
    ++scene.seed;
  }
  first.sim_ms = sim / seeds;
  first.deform_ms = deform / seeds;
  return first;
}

// The meshes, in the order the proxies name their poses, and the proxies.
struct Inputs {
  std::vector<TriMesh> meshes;
  std::vector<Proxy> proxies;
};
Inputs load_inputs(const std::string& rest_path, const std::vector<std::string>& pose_paths,
                   const std::vector<std::string>& proxy_paths) {
  Inputs in;
  const LoadedMesh rest = load_mesh(rest_path);
  in.meshes = {rest.mesh};
  for (const auto& p : pose_paths) in.meshes.push_back(load_pose(p, rest));
  in.proxies.resize(proxy_paths.size());
  for (size_t i = 0; i < proxy_paths.size(); ++i) {
    Proxy& proxy = in.proxies[i];
    const Status s = load_file(proxy_paths[i].c_str(), &proxy);
    if (s != SPX_OK) fail_input(proxy_paths[i], std::string("cannot load: ") + status_string(s));
    for (uint32_t k = 1; k < proxy.pose_count() && k <= pose_paths.size(); ++k)
      if (stem_of(pose_paths[k - 1]) != proxy.pose_name(k))
        fail_input(proxy_paths[i], "pose " + std::to_string(k) + " is '" + proxy.pose_name(k) + "' but --pose " +
                                       std::to_string(k) + " is " + pose_paths[k - 1]);
  }
  return in;
}

// Configurations: each proxy as Bullet's compound and with the sphere-set narrow phase, then
// the triangle mesh (the baseline, last) with the finest proxy's blend sites.
std::vector<CarAsset> configurations(const Inputs& in) {
  std::vector<CarAsset> assets;
  size_t finest = 0;
  for (size_t i = 0; i < in.proxies.size(); ++i) {
    const std::string n = std::to_string(in.proxies[i].sphere_count());
    assets.push_back(make_car_asset("compound-" + n, true, in.proxies[i], in.meshes));
    assets.push_back(make_car_asset("sphereset-" + n, true, in.proxies[i], in.meshes));
    assets.back().sphere_set = true;
    if (in.proxies[i].sphere_count() > in.proxies[finest].sphere_count()) finest = i;
  }
  assets.push_back(make_car_asset("triangle-mesh", false, in.proxies[finest], in.meshes));
  return assets;
}

// The same scene over `seeds` consecutive seeds, monitored (never timed).
std::vector<RunStats> monitored_seeds(const CarAsset& asset, SceneOptions o, int seeds) {
  o.monitor = true;
  const uint32_t first = o.seed;
  std::vector<RunStats> runs;
  for (int k = 0; k < seeds; ++k) {
    o.seed = first + uint32_t(k);
    runs.push_back(run_scene(asset, o));
  }
  return runs;
}

json paths_json(const RunStats& m) {
  json paths = json::array();
  for (const auto& car : m.path) {
    json xyz = json::array();
    for (const auto& p : car) xyz.push_back({p.x(), p.y(), p.z()});
    paths.push_back(xyz);
  }
  return {{"times_s", m.sample_times}, {"cars", paths}};
}

// One configuration's entry: medians of its timed runs, ratios to the baseline's, and what its
// monitored run measured; printed as a table row too.
json config_json(const CarAsset& asset, const std::vector<RunStats>& timed, const RunStats& m, const json& safety,
                 const std::vector<RunStats>& baseline) {
  auto median_of = [](const std::vector<RunStats>& runs, auto field) {
    std::vector<double> v;
    for (const auto& run : runs) v.push_back(field(run));
    return median(v);
  };
  auto total_of = [](const RunStats& r) { return r.total_ms(); };
  auto sim_of = [](const RunStats& r) { return r.sim_ms; };
  const double base_total = median_of(baseline, total_of), base_sim = median_of(baseline, sim_of);
  bool repeatable = true;
  json runs = json::array();
  for (const auto& run : timed) {
    repeatable = repeatable && run.state_hash == m.state_hash;  // first seed's final state
    runs.push_back({{"sim_ms", run.sim_ms}, {"deform_ms", run.deform_ms}, {"total_ms", run.total_ms()}});
  }
  const double total = median_of(timed, total_of), sim = median_of(timed, sim_of);
  json entry = {{"name", asset.name},
                {"spheres_per_car", asset.sphere_count()},
                {"triangles_per_car", asset.rest.triangles.size()},
                {"sim_ms", sim},
                {"deform_ms", median_of(timed, [](const RunStats& r) { return r.deform_ms; })},
                {"total_ms", total},
                {"speedup", base_total / total},
                {"sim_speedup", base_sim / sim},
                {"runs", runs},
                {"steps", m.steps},
                {"contacts", m.contacts},
                {"reblends", m.reblends},
                {"max_weight_moved", m.max_weight_moved},
                {"repeatable", repeatable},
                {"safety", safety},
                {"paths", paths_json(m)}};
  if (asset.spheres) entry["error"] = error_json(m);
  std::printf("%-16s %8zu %10.1f %10.1f %10.1f %7.1fx %10llu %12s %10s\n", asset.name.c_str(), asset.sphere_count(), sim,
              entry["deform_ms"].get<double>(), total, base_total / total, (unsigned long long)m.contacts,
              asset.spheres ? num(entry["error"]["median_of_medians_m"].get<double>()).c_str() : "-",
              asset.spheres ? num(entry["error"]["max_m"].get<double>()).c_str() : "-");
  return entry;
}

// The stability sweep: every configuration at larger steps and higher launch speeds.
json stability_sweep(const std::vector<CarAsset>& assets, const SceneOptions& scene, int seeds, Log& log) {
  json sweep = json::array();
  std::printf("\n%-16s %6s %6s %8s %8s %12s %12s %8s\n", "config", "dt", "speed", "ground", "car", "contact pen",
              "ground pen", "energy");
  for (double dt : {1.0 / 60, 1.0 / 30, 1.0 / 15})
    for (double speed : {1.0, 1.5, 2.0})
      for (const auto& asset : assets) {
        SceneOptions o = scene;
        o.dt = dt;
        o.speed_scale = speed;
        o.sample_every = 1 << 30;  // error traces are not part of the sweep
        log.info("stability: " + asset.name + " at dt 1/" + std::to_string(int(std::lround(1 / dt))) +
                 ", launch speed x" + num(speed));
        json row = safety_json(monitored_seeds(asset, o, seeds));
        row["name"] = asset.name;
        row["dt_s"] = dt;
        row["speed_scale"] = speed;
        sweep.push_back(row);
        std::printf("%-16s  1/%-3d %6.1f %8d %8d %12.3f %12.3f %8.2f%s\n", asset.name.c_str(), int(std::lround(1 / dt)),
                    speed, row["ground_tunnels"].get<int>(), row["car_tunnels"].get<int>(),
                    row["max_contact_penetration_m"].get<double>(), row["max_ground_penetration_m"].get<double>(),
                    row["max_energy_ratio"].get<double>(), row["energy_blew_up"].get<bool>() ? " blew up" : "");
      }
  return sweep;
}

}  // namespace

int main(int argc, char** argv) {
  Tool tool("crash-bench", "Car crash benchmark: sphere proxies against triangle meshes in Bullet (paper, Table 1).");
  std::string rest_path, out_path;
  std::vector<std::string> pose_paths, proxy_paths;
  int repeats = 5, seeds = 3;
  SceneOptions scene;
  bool stability = true;
  std::string only;
  tool.app.add_option("--rest", rest_path, "Rest mesh M_0")->required()->check(CLI::ExistingFile);
  tool.app.add_option("--pose", pose_paths, "Example poses M_1..M_e, in the proxies' pose order")->required();
  tool.app.add_option("--proxy", proxy_paths, ".spx proxies of the car, one configuration each")->required();
  tool.app.add_option("--json", out_path, "Write the results here")->required();
  tool.app.add_option("--repeats", repeats, "Timed runs per configuration (median reported)")->check(CLI::Range(1, 100));
  tool.app.add_option("--seconds", scene.seconds, "Simulated time per run")->check(CLI::Range(0.1, 600.0));
  tool.app.add_option("--cars", scene.cars, "Cars in the scene")->check(CLI::Range(1, 64));
  tool.app.add_option("--seed", scene.seed, "First seed for lane, yaw and speed jitter");
  tool.app.add_option("--seeds", seeds, "Crashes (consecutive seeds) per run")->check(CLI::Range(1, 100));
  tool.app.add_flag("!--no-stability", stability, "Skip the larger-step / higher-speed sweep");
  tool.app.add_option("--profile", only, "Only time this configuration (for a profiler); no baseline, no JSON");
  return tool.run(argc, argv, [&] {
    const Inputs inputs = load_inputs(rest_path, pose_paths, proxy_paths);  // the assets point into it
    const std::vector<CarAsset> assets = configurations(inputs);
    if (!only.empty()) {
      const auto it = std::find_if(assets.begin(), assets.end(), [&](const CarAsset& a) { return a.name == only; });
      if (it == assets.end()) fail_usage(only, "no such configuration");
      for (int r = 0; r < repeats; ++r) {
        const RunStats run = run_seeds(*it, scene, seeds);
        std::printf("%s: sim %.1f ms, deform %.1f ms\n", only.c_str(), run.sim_ms, run.deform_ms);
      }
      return;
    }
    // Monitored runs first (never timed), then timed repeats interleaved across configurations
    // so that machine noise hits every configuration alike.
    std::vector<RunStats> monitored;
    std::vector<json> safety;
    for (const auto& asset : assets) {
      tool.log.info("monitored runs: " + asset.name);
      const std::vector<RunStats> runs = monitored_seeds(asset, scene, seeds);
      safety.push_back(safety_json(runs));
      monitored.push_back(runs.front());  // Figure 5 and the paths show the first crash
    }
    std::vector<std::vector<RunStats>> timed(assets.size());
    for (int r = 0; r < repeats; ++r) {
      tool.log.info("timed round " + std::to_string(r + 1) + "/" + std::to_string(repeats));
      for (size_t c = 0; c < assets.size(); ++c) timed[c].push_back(run_seeds(assets[c], scene, seeds));
    }
    json configs = json::array();
    std::printf("%-16s %8s %10s %10s %10s %8s %10s %12s %10s\n", "config", "spheres", "sim ms", "deform ms", "total ms",
                "speedup", "contacts", "err median", "err max");
    for (size_t c = 0; c < assets.size(); ++c)
      configs.push_back(config_json(assets[c], timed[c], monitored[c], safety[c], timed.back()));
    const json sweep = stability ? stability_sweep(assets, scene, seeds, tool.log) : json::array();
    json result = {{"generator", std::string("crash-bench (spx) ") + spx::version_string()},
                   {"scene",
                    {{"cars", scene.cars},
                     {"seconds", scene.seconds},
                     {"dt_s", scene.dt},
                     {"seed", scene.seed},
                     {"seeds", seeds},
                     {"impulse_threshold", scene.impulse_threshold}}},
                   {"repeats", repeats},
                   {"configs", configs},
                   {"stability", sweep}};
    write_json_atomic(out_path, result);
    tool.report = {{"json", out_path}, {"configs", configs.size()}};
  });
}
