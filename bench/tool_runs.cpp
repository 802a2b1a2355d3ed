#include "tool_runs.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <exception>
#include <fstream>
#include <mutex>
#include <stdexcept>
#include <thread>

#include "core/atomic_file.hpp"
#include "mesh/mesh.hpp"
#include "io/pose_manifest.hpp"
#include "io/skin_file.hpp"
#include "mesh/split.hpp"
#include "posemap/skinned_map.hpp"

extern char** environ;

namespace spx::bench {
namespace fs = std::filesystem;
using json = nlohmann::json;

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  return values.empty() ? 0 : values[values.size() / 2];
}

namespace {

json read_json(const std::string& path) {
  std::ifstream in(path);
  return json::parse(in);
}

// The pose-map report's sphere count.
size_t spheres_in_report(const std::string& report) { return read_json(report).at("sphere_count").get<size_t>(); }

// Throws unless the run from the cache wrote what the fresh run wrote: the proxies byte for
// byte, and the spheres files but for the field each names (`source`, another route's file).
void check_same_outputs(const std::string& fresh_proxy, const std::string& cached_proxy,
                        const std::string& fresh_spheres = "", const std::string& cached_spheres = "") {
  bool same = read_file(fresh_proxy) == read_file(cached_proxy);
  if (same && !fresh_spheres.empty()) {
    json a = read_json(fresh_spheres), b = read_json(cached_spheres);
    a.erase("source");
    b.erase("source");
    same = a == b;
  }
  if (!same) throw std::runtime_error(cached_proxy + ": the run from the cache wrote other spheres than " + fresh_proxy);
}

// A tool run two ways (0: spaced, 1: --every-vertex) in turn `runs` times: each way's times, its
// most memory and its last report. `run_way(every, out)` is the way's command, writing its
// report to out + ".report.json".
struct BothWays {
  std::vector<double> seconds[2];
  double peak[2] = {0, 0};
  json report[2];
};
BothWays run_both_ways(const std::string& tools, int runs, const std::string& out_stem,
                       const std::function<std::vector<std::string>(int, const std::string&)>& run_way) {
  BothWays b;
  for (int r = 0; r < runs; ++r)
    for (int every = 0; every < 2; ++every) {
      const std::string out = out_stem + (every ? "-every" : "-spaced");
      const ToolRun run = run_tool(tools, run_way(every, out));
      b.seconds[every].push_back(run.seconds);
      b.peak[every] = std::max(b.peak[every], run.peak_gib);
      b.report[every] = read_json(out + ".report.json");
    }
  return b;
}

}  // namespace

std::string tools_dir_beside_this_program() {
  return (fs::read_symlink("/proc/self/exe").parent_path().parent_path() / "apps").string();
}

ToolRun run_tool(const std::string& tools_dir, const std::vector<std::string>& argv) {
  std::vector<std::string> args = argv;
  args[0] = tools_dir + "/" + argv[0];
  std::vector<char*> c_args;
  for (std::string& a : args) c_args.push_back(a.data());
  c_args.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&actions, 2, "/dev/null", O_WRONLY, 0);
  const auto start = std::chrono::steady_clock::now();
  pid_t pid = 0;
  const int spawned = posix_spawn(&pid, c_args[0], &actions, nullptr, c_args.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  std::string command;
  for (const std::string& a : argv) command += (command.empty() ? "" : " ") + a;
  if (spawned != 0) throw std::runtime_error("cannot start " + args[0]);
  int status = 0;
  rusage usage{};
  wait4(pid, &status, 0, &usage);
  ToolRun out;
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  out.peak_gib = double(usage.ru_maxrss) / (1024.0 * 1024.0);
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) throw std::runtime_error("failed: " + command);
  return out;
}

json route_case(const std::string& tools, const std::string& name, const std::string& rest,
                const std::vector<std::string>& poses, const std::string& work, int repeats, const Log& log) {
  const std::string dir = work + "/" + name;
  fs::create_directories(dir);
  std::vector<std::string> pose_args;
  for (const std::string& p : poses) {
    pose_args.push_back("--pose");
    pose_args.push_back(p);
  }
  struct Route {
    std::string name;
    std::vector<std::string> pack, map;
    std::vector<double> sdf, pack_s, map_s, total;
    double peak = 0;
    size_t spheres = 0;
  };
  // The default route again with both tools' --cache, written by one run before the timed ones:
  // an artist's second run. Its outputs must be the fresh default route's.
  const std::string cache = dir + "/cache";
  fs::remove_all(cache);
  std::vector<Route> routes = {{"paper", {"--method", "greedy"}, {"--map-given"}, {}, {}, {}, {}},
                               {"default", {}, {}, {}, {}, {}, {}},
                               {"cached", {"--cache", cache}, {"--cache", cache}, {}, {}, {}, {}}};
  for (int r = -1; r < repeats; ++r)
    for (Route& route : routes) {
      if (r < 0 && route.name != "cached") continue;  // the untimed run that writes the cache
      const std::string field = dir + "/" + route.name + ".vdb", spheres = dir + "/" + route.name + ".spheres.json";
      const std::string report = dir + "/" + route.name + ".report.json";
      std::vector<std::string> pack{"sphere-pack", field, "-o", spheres, "--mesh", rest, "-q"};
      pack.insert(pack.end(), route.pack.begin(), route.pack.end());
      std::vector<std::string> map{"pose-map", "--rest", rest, "--spheres", spheres, "-o",
                                   dir + "/" + route.name + ".proxy.json", "--report", report, "-q"};
      map.insert(map.end(), pose_args.begin(), pose_args.end());
      map.insert(map.end(), route.map.begin(), route.map.end());
      const ToolRun sdf = run_tool(tools, {"sdf-build", rest, "-o", field, "-q"});
      const ToolRun packed = run_tool(tools, pack);
      const ToolRun mapped = run_tool(tools, map);
      if (r < 0) continue;
      if (route.name == "cached")
        check_same_outputs(dir + "/default.proxy.json", dir + "/cached.proxy.json", dir + "/default.spheres.json",
                           spheres);
      route.sdf.push_back(sdf.seconds);
      route.pack_s.push_back(packed.seconds);
      route.map_s.push_back(mapped.seconds);
      route.total.push_back(sdf.seconds + packed.seconds + mapped.seconds);
      route.peak = std::max({route.peak, sdf.peak_gib, packed.peak_gib, mapped.peak_gib});
      route.spheres = spheres_in_report(report);
    }
  json out = {{"mesh", name}, {"poses", poses.size()}};
  for (const Route& route : routes)
    out[route.name] = {{"sdf_s", median(route.sdf)},     {"pack_s", median(route.pack_s)},
                       {"pose_map_s", median(route.map_s)}, {"total_s", median(route.total)},
                       {"peak_gib", route.peak},           {"spheres", route.spheres}};
  // The medians of per-repeat ratios: each pair ran side by side.
  const auto ratio = [&](size_t a, size_t b) {
    std::vector<double> ratios;
    for (int r = 0; r < repeats; ++r) ratios.push_back(routes[a].total[size_t(r)] / routes[b].total[size_t(r)]);
    return median(ratios);
  };
  out["default_over_paper"] = ratio(1, 0);
  out["cached_over_paper"] = ratio(2, 0);
  out["cached_over_default"] = ratio(2, 1);
  say(log, "%s: paper route %.2f s, default route %.2f s (%.2fx), from the cache %.2f s (%.2fx)", name.c_str(),
      out["paper"]["total_s"].get<double>(), out["default"]["total_s"].get<double>(), ratio(1, 0),
      out["cached"]["total_s"].get<double>(), ratio(2, 0));
  out["triangles"] = load_mesh(rest).mesh.triangles.size();
  return out;
}

json frame_sweep(const std::string& tools, const ClipSweep& clip, const std::vector<size_t>& frames,
                 const std::string& work, int repeats, bool with_cache, const Log& log) {
  const std::string dir = work + "/" + clip.name;
  fs::create_directories(dir);
  auto poses_of = [&](size_t n) { return dir + "/frames-" + std::to_string(n); };
  for (size_t n : frames) {
    std::vector<std::string> extract{"pose-extract", clip.asset, "-o", poses_of(n), "-q"};
    extract.insert(extract.end(), clip.extract.begin(), clip.extract.end());
    const std::vector<std::string> which = clip.frames_option(n);
    extract.insert(extract.end(), which.begin(), which.end());
    run_tool(tools, extract);
  }
  // Every extraction has the same rest: its field and spheres built once.
  const std::string rest = poses_of(frames[0]) + "/rest.obj";
  const std::string field = dir + "/rest.vdb", spheres = dir + "/rest.spheres.json";
  run_tool(tools, {"sdf-build", rest, "-o", field, "-q"});
  run_tool(tools, {"sphere-pack", field, "-o", spheres, "--mesh", rest, "-q"});
  // The counts take turns within each repeat (4, 8, ..., 48, then 4, 8, ... again), so that a
  // ratio compares runs made side by side, not one count's runs before the next's. Each fresh
  // run is followed by one with --cache (written by a run before the timed ones), whose proxy
  // must be the fresh one's.
  const std::string cache = dir + "/cache";
  fs::remove_all(cache);
  const auto pose_map = [&](const std::string& poses, bool cached) {
    std::vector<std::string> argv{"pose-map", "--manifest", poses + "/poses.json", "--spheres", spheres, "-o",
                                  poses + (cached ? "/proxy-cached.json" : "/proxy.json"), "-q"};
    if (cached) argv.insert(argv.end(), {"--cache", cache});
    else argv.insert(argv.end(), {"--report", poses + "/report.json"});
    return run_tool(tools, argv);
  };
  if (with_cache)
    for (size_t n : frames) pose_map(poses_of(n), true);
  std::vector<std::vector<double>> seconds(frames.size()), cached_seconds(frames.size());
  std::vector<double> peak(frames.size(), 0);
  for (int r = 0; r < repeats; ++r)
    for (size_t k = 0; k < frames.size(); ++k) {
      if (r > 0 && frames[k] > 64) continue;  // one run past 64 frames
      const std::string poses = poses_of(frames[k]);
      const ToolRun run = pose_map(poses, false);
      seconds[k].push_back(run.seconds);
      peak[k] = std::max(peak[k], run.peak_gib);
      if (!with_cache) continue;
      cached_seconds[k].push_back(pose_map(poses, true).seconds);
      check_same_outputs(poses + "/proxy.json", poses + "/proxy-cached.json");
    }
  // The median of the per-repeat ratios to the first count: each pair ran side by side.
  const auto over_first = [](const std::vector<std::vector<double>>& runs, size_t k) {
    std::vector<double> ratios;
    for (size_t r = 0; r < runs[k].size(); ++r) ratios.push_back(runs[k][r] / runs[0][r]);
    return median(ratios);
  };
  json rows = json::array();
  for (size_t k = 0; k < frames.size(); ++k) {
    json row = {{"frames", frames[k]},
                {"pose_map_s", median(seconds[k])},
                {"runs", seconds[k].size()},
                {"pose_map_runs_s", seconds[k]},
                {"peak_gib", peak[k]},
                {"spheres", spheres_in_report(poses_of(frames[k]) + "/report.json")},
                {"over_first", over_first(seconds, k)}};
    say(log, "%s, %zu frames: pose-map %.2f s (%.2fx %zu frames), %.2f GiB", clip.name.c_str(), frames[k],
        median(seconds[k]), over_first(seconds, k), frames[0], peak[k]);
    if (with_cache) {
      row["cached_s"] = median(cached_seconds[k]);
      row["cached_runs_s"] = cached_seconds[k];
      row["cached_over_first"] = over_first(cached_seconds, k);
      say(log, "%s, %zu frames from the cache: pose-map %.2f s (%.2fx %zu frames)", clip.name.c_str(), frames[k],
          median(cached_seconds[k]), over_first(cached_seconds, k), frames[0]);
    }
    rows.push_back(row);
  }
  return {{"clip", clip.name}, {"rows", rows}, {"triangles", load_mesh(rest).mesh.triangles.size()}};
}

json dense_case(const std::string& tools, const std::string& name, const std::string& rest, int split, size_t budget,
                const std::string& work, int repeats, const Log& log) {
  fs::create_directories(work);
  const std::string label = name + "-x" + std::to_string(1 << (2 * split));
  const std::string mesh = work + "/" + label + ".obj", field = work + "/" + label + ".vdb";
  size_t triangles = 0, vertices = 0;
  {  // freed before the tools run: a child's peak memory starts from this process's own
    const TriMesh dense = split_at_midpoints(load_mesh(rest).mesh, split);
    triangles = dense.triangles.size();
    vertices = dense.vertices.size();
    write_file_atomic(mesh, to_obj(dense, label));
  }
  run_tool(tools, {"sdf-build", mesh, "-o", field, "-q"});
  const int runs = triangles > 1000000 ? 1 : repeats;
  json rows = json::array();
  // Budget mode where every vertex's run is minutes, not an hour (under a million triangles).
  std::vector<size_t> modes = {0};
  if (budget > 0 && triangles <= 1000000) modes.push_back(budget);
  for (size_t spheres : modes) {
    const auto [seconds, peak, report] =
        run_both_ways(tools, runs, work + "/" + label, [&](int every, const std::string& out) {
          std::vector<std::string> argv = {"sphere-pack", field, "-o", out + ".spheres.json", "--mesh", mesh,
                                           "--report", out + ".report.json", "-q"};
          if (spheres > 0) argv.insert(argv.end(), {"--max-spheres", std::to_string(spheres)});
          if (every) argv.push_back("--every-vertex");
          return argv;
        });
    json row = {{"mode", spheres > 0 ? std::to_string(spheres) + " spheres" : "the default tolerance"}, {"runs", runs}};
    for (int every = 0; every < 2; ++every) {
      const json& cover = report[every].at("cover");
      row[every ? "every_vertex" : "spaced"] = {{"s", median(seconds[every])}, {"peak_gib", peak[every]},
                                                {"spheres", report[every].at("sphere_count")},
                                                {"max_error", cover.at("max_error")}, {"median_error", cover.at("median_error")},
                                                {"samples_covered", cover.at("samples_covered")}};
    }
    row["every_over_spaced"] = median(seconds[1]) / median(seconds[0]);
    say(log, "%s (%zu triangles), %s: spaced %.1f s %.2f GiB %d spheres, every vertex %.1f s %.2f GiB %d spheres",
        label.c_str(), triangles, row["mode"].get<std::string>().c_str(), median(seconds[0]), peak[0],
        row["spaced"]["spheres"].get<int>(), median(seconds[1]), peak[1], row["every_vertex"]["spheres"].get<int>());
    rows.push_back(row);
  }
  return {{"mesh", label}, {"triangles", triangles}, {"vertices", vertices}, {"rows", rows}};
}

namespace {

// pose-map on the dense poses in `dir` (its rest.obj, and `poses`: the tool's pose arguments),
// spaced against every vertex, from sphere-pack's spheres at the default tolerance: the row.
json map_dense_both_ways(const std::string& tools, const std::string& label, const std::string& dir,
                         std::vector<std::string> poses, size_t pose_count, size_t triangles, size_t vertices,
                         int repeats, const Log& log) {
  run_tool(tools, {"sdf-build", dir + "/rest.obj", "-o", dir + "/rest.vdb", "-q"});
  run_tool(tools, {"sphere-pack", dir + "/rest.vdb", "--mesh", dir + "/rest.obj", "-o", dir + "/rest.spheres.json", "-q"});
  poses.insert(poses.end(), {"--spheres", dir + "/rest.spheres.json"});
  const int runs = triangles > 500000 ? 1 : repeats;
  const auto [seconds, peak, report] = run_both_ways(tools, runs, dir + "/map", [&](int every, const std::string& out) {
    std::vector<std::string> argv = {"pose-map", "-o", out + ".proxy.json", "--report", out + ".report.json", "-q"};
    argv.insert(argv.end(), poses.begin(), poses.end());
    if (every) argv.push_back("--every-vertex");
    return argv;
  });
  json row = {{"mesh", label}, {"triangles", triangles}, {"vertices", vertices}, {"poses", pose_count}, {"runs", runs}};
  for (int every = 0; every < 2; ++every) {
    double worst = 0, medians = 0;
    for (const json& pose : report[every].at("poses")) {
      worst = std::max(worst, pose.at("error").at("max").get<double>());
      medians += pose.at("error").at("median").get<double>() / double(report[every].at("poses").size());
    }
    const json& sel = report[every].at("selection");
    row[every ? "every_vertex" : "spaced"] = {{"s", median(seconds[every])}, {"peak_gib", peak[every]},
                                              {"spheres", report[every].at("sphere_count")}, {"max_error", worst},
                                              {"mean_median_error", medians}, {"samples", sel.at("samples")},
                                              {"rounds", sel.at("frames").at("rounds")},
                                              {"spaced_vertices", sel.at("spaced_vertices")}};
  }
  row["every_over_spaced"] = median(seconds[1]) / median(seconds[0]);
  say(log, "%s poses (%zu triangles): pose-map spaced %.1f s %.2f GiB %d spheres, every vertex %.1f s %.2f GiB %d spheres",
      label.c_str(), triangles, median(seconds[0]), peak[0], row["spaced"]["spheres"].get<int>(), median(seconds[1]),
      peak[1], row["every_vertex"]["spheres"].get<int>());
  return row;
}

}  // namespace

json dense_poses_case(const std::string& tools, const std::string& name, const std::string& rest,
                      const std::vector<std::string>& poses, int split, const std::string& work, int repeats,
                      const Log& log) {
  const std::string label = name + "-x" + std::to_string(1 << (2 * split)), dir = work + "/" + label;
  fs::create_directories(dir);
  size_t triangles = 0, vertices = 0;
  std::vector<std::string> args = {"--rest", dir + "/rest.obj"};
  {  // freed before the tools run: a child's peak memory starts from this process's own
    const LoadedMesh loaded = load_mesh(rest);
    const TriMesh dense = split_at_midpoints(loaded.mesh, split);
    triangles = dense.triangles.size();
    vertices = dense.vertices.size();
    write_file_atomic(dir + "/rest.obj", to_obj(dense, label));
    for (size_t k = 0; k < poses.size(); ++k) {
      const std::string path = dir + "/pose-" + std::to_string(k) + ".obj";
      write_file_atomic(path, to_obj(split_at_midpoints(load_pose(poses[k], loaded), split), label));
      args.insert(args.end(), {"--pose", path});
    }
  }
  return map_dense_both_ways(tools, label, dir, args, poses.size(), triangles, vertices, repeats, log);
}

json dense_skinned_case(const std::string& tools, const std::string& name, const std::string& asset,
                        const std::vector<std::string>& extract, int split, const std::string& work, int repeats,
                        const Log& log) {
  const std::string label = name + "-x" + std::to_string(1 << (2 * split)), dir = work + "/" + label;
  const std::string from = dir + "/extracted";
  std::vector<std::string> argv = {"pose-extract", asset, "-o", from, "-q"};
  argv.insert(argv.end(), extract.begin(), extract.end());
  run_tool(tools, argv);
  size_t triangles = 0, vertices = 0, poses = 0;
  {  // freed before the tools run: a child's peak memory starts from this process's own
    const PoseManifest manifest = read_pose_manifest(from + "/poses.json");
    const LoadedMesh loaded = load_mesh(from + "/" + manifest.rest);
    SkinFile skin = read_skin_file(from + "/" + manifest.skin);
    skin.vertex_weights =
        weights_for_vertices(skin, loaded.mesh.vertices, 1e-6 * loaded.mesh.diagonal(), from + "/" + manifest.skin);
    // Each frame skinned afresh from its joint matrices, as pose-map checks a rigged frame.
    const SplitSkinned dense = split_skinned(loaded.mesh, std::move(skin), split);
    triangles = dense.rest.triangles.size();
    vertices = dense.rest.vertices.size();
    poses = manifest.poses.size();
    write_file_atomic(dir + "/" + manifest.rest, to_obj(dense.rest, label));
    for (size_t k = 0; k < poses; ++k)
      write_file_atomic(dir + "/" + manifest.poses[k].file, to_obj(dense.poses[k], manifest.poses[k].name));
    write_file_atomic(dir + "/" + manifest.skin, skin_to_json(dense.skin).dump());
    write_file_atomic(dir + "/poses.json", manifest_to_json(manifest).dump(1));
  }
  return map_dense_both_ways(tools, label, dir, {"--manifest", dir + "/poses.json"}, poses, triangles, vertices,
                             repeats, log);
}

namespace {

// The default route on one chain in `dir`, every tool given `extra` (its --threads): the most
// memory one of its processes took.
double run_default_route(const std::string& tools, const RouteBody& chain, const std::string& dir,
                         const std::vector<std::string>& extra) {
  fs::create_directories(dir);
  std::vector<std::string> sdf{"sdf-build", chain.rest, "-o", dir + "/rest.vdb", "-q"};
  std::vector<std::string> pack{"sphere-pack", dir + "/rest.vdb", "--mesh", chain.rest, "-o", dir + "/rest.spheres.json", "-q"};
  std::vector<std::string> map{"pose-map", "--rest", chain.rest, "--spheres", dir + "/rest.spheres.json",
                               "-o", dir + "/body.proxy.json", "-q"};
  for (const std::string& p : chain.poses) map.insert(map.end(), {"--pose", p});
  double peak = 0;
  for (std::vector<std::string>* argv : {&sdf, &pack, &map}) {
    argv->insert(argv->end(), extra.begin(), extra.end());
    peak = std::max(peak, run_tool(tools, *argv).peak_gib);
  }
  return peak;
}

}  // namespace

json batch_case(const std::string& tools, const std::vector<RouteBody>& chains, const std::string& work, int repeats,
                const Log& log) {
  struct Way {
    std::string name;
    size_t at_once;
    std::vector<std::string> extra;
    std::vector<double> seconds;
    double peak = 0;
  };
  std::vector<Way> ways = {{"one_at_a_time", 1, {}, {}},
                           {"two_at_a_time_one_thread_each", 2, {"--threads", "1"}, {}},
                           {"two_at_a_time_every_core_each", 2, {}, {}}};
  std::vector<std::string> proxies(chains.size());  // the first way's, which every way must write
  // A chain keeps its folder whatever the way, so that the paths its files record are the same.
  const auto folder = [&](size_t k) { return work + "/batch/" + std::to_string(k) + "-" + chains[k].name; };
  for (int r = 0; r < repeats; ++r)
    for (Way& way : ways) {
      // Each worker takes the next chain until none is left.
      std::atomic<size_t> next{0};
      std::mutex lock;
      std::exception_ptr failed;
      auto work_through = [&] {
        try {
          for (size_t k = next++; k < chains.size(); k = next++) {
            const double peak = run_default_route(tools, chains[k], folder(k), way.extra);
            std::lock_guard<std::mutex> held(lock);
            way.peak = std::max(way.peak, peak);
          }
        } catch (...) {
          std::lock_guard<std::mutex> held(lock);
          failed = std::current_exception();
        }
      };
      const auto start = std::chrono::steady_clock::now();
      std::vector<std::thread> workers;
      for (size_t w = 0; w < way.at_once; ++w) workers.emplace_back(work_through);
      for (std::thread& w : workers) w.join();
      way.seconds.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
      if (failed) std::rethrow_exception(failed);
      for (size_t k = 0; k < chains.size(); ++k) {
        const std::string proxy = folder(k) + "/body.proxy.json";
        const std::string bytes = read_file(proxy);
        if (proxies[k].empty()) proxies[k] = bytes;
        if (bytes != proxies[k]) throw std::runtime_error(proxy + ": " + way.name + " wrote another proxy than the first way");
      }
    }
  json out = {{"chains", json::array()}, {"ways", json::array()}};
  for (const RouteBody& c : chains) out["chains"].push_back(c.name);
  for (const Way& way : ways) {
    std::vector<double> ratios;
    for (int r = 0; r < repeats; ++r) ratios.push_back(way.seconds[size_t(r)] / ways[0].seconds[size_t(r)]);
    out["ways"].push_back({{"way", way.name}, {"at_once", way.at_once}, {"threads_each", way.extra.empty() ? 0 : 1},
                           {"seconds", median(way.seconds)}, {"runs_s", way.seconds}, {"over_first", median(ratios)},
                           {"peak_gib", way.peak}});
  }
  const json& w = out["ways"];
  say(log, "batch of %zu default routes: one at a time %.2f s; two at a time on one thread each %.2f s (%.2fx), on every "
      "core each %.2f s (%.2fx)", chains.size(), w[0]["seconds"].get<double>(), w[1]["seconds"].get<double>(),
      w[1]["over_first"].get<double>(), w[2]["seconds"].get<double>(), w[2]["over_first"].get<double>());
  return out;
}

}  // namespace spx::bench
