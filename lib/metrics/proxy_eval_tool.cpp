#include "metrics/proxy_eval_tool.hpp"

#include <cstdio>
#include <filesystem>

#include "core/atomic_file.hpp"
#include "core/error.hpp"
#include "core/subject.hpp"
#include "io/scene.hpp"

namespace spx {

std::vector<TriMesh> load_pose_meshes(const std::string& rest_path, const std::vector<std::string>& pose_paths,
                                      const ProxyModel& proxy, const std::string& proxy_path, Log& log) {
  if (pose_paths.size() + 1 != proxy.poses.size())
    fail_option("poses", proxy_path + " has " + std::to_string(proxy.poses.size() - 1) + " example poses; " +
                             std::to_string(pose_paths.size()) + " pose files were given");
  const LoadedMesh rest = load_mesh(rest_path);
  std::vector<TriMesh> meshes{rest.mesh};
  for (size_t i = 0; i < pose_paths.size(); ++i) {
    meshes.push_back(load_pose(pose_paths[i], rest));
    if (stem_of(pose_paths[i]) != proxy.poses[i + 1].name)
      log.warn(pose_paths[i] + ": the proxy calls pose " + std::to_string(i + 1) + " '" + proxy.poses[i + 1].name +
               "'; poses are matched by order");
  }
  return meshes;
}

void proxy_eval_files(const std::string& proxy_path, const std::string& rest_path, const std::vector<std::string>& pose_paths,
                      const EvalToolOptions& opt, Log& log, json& report) {
  std::string ext;
  if (!opt.colors.empty()) {
    ext = std::filesystem::path(opt.colors).extension().string();
    if (ext != ".glb" && ext != ".ply") fail_usage(opt.colors, "colours go to .glb or .ply");
  }
  const ProxyModel proxy = read_proxy_file(proxy_path);
  std::vector<TriMesh> meshes;
  {
    StageTimer t(log, "load");
    meshes = load_pose_meshes(rest_path, pose_paths, proxy, proxy_path, log);
  }
  EvalResult r;
  {
    StageTimer t(log, "evaluate");
    r = about_file(proxy_path, [&] { return evaluate_proxy(proxy, meshes, opt.eval, log); });
  }
  char line[256];
  for (const auto& p : r.report["poses"]) {
    std::snprintf(line, sizeof line, "%-12s median %.4g p95 %.4g max %.4g coverage %.3f", p["name"].get<std::string>().c_str(),
                  p["median"].get<double>(), p["p95"].get<double>(), p["max"].get<double>(), p["coverage"].get<double>());
    log.info(line);
  }
  if (r.report["blends"].contains("max")) {
    std::snprintf(line, sizeof line, "%-12s median %.4g max %.4g over %d blends", "blends",
                  r.report["blends"]["median"].get<double>(), r.report["blends"]["max"].get<double>(), opt.eval.blends);
    log.info(line);
  }
  if (!opt.colors.empty()) {
    StageTimer t(log, "colors");
    double scale = opt.color_scale;
    if (!(scale > 0))
      for (const auto& p : r.report["poses"]) scale = std::max(scale, p["max"].get<double>());
    std::vector<PoseError> shown = r.poses;
    write_file_atomic(opt.colors, encode_error_scene(shown, ext, opt.color_pose, scale, 1.25 * meshes[0].bounds().sizes().x()));
    report["colors"] = {{"file", opt.colors}, {"scale", scale}};
  }
  report.update(r.report);
  report["input"] = proxy_path;
  report["sphere_count"] = proxy.sphere_count();
}

}  // namespace spx
