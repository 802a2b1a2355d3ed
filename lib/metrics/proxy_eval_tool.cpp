#include "metrics/proxy_eval_tool.hpp"

#include <algorithm>
#include <cstdio>
#include <memory>

#include "core/atomic_file.hpp"
#include "core/error.hpp"
#include "core/file_kind.hpp"
#include "core/format.hpp"
#include "core/pose_lines.hpp"
#include "core/subject.hpp"
#include "extract/asset.hpp"
#include "io/pose_manifest.hpp"
#include "io/scene.hpp"
#include "io/spx_writer.hpp"
#include "metrics/rest_match.hpp"

namespace spx {

std::vector<TriMesh> load_pose_meshes(const std::string& rest_path, const std::vector<std::string>& pose_paths,
                                      const ProxyModel& proxy, const std::string& proxy_path, Log& log,
                                      const std::string& manifest) {
  if (pose_paths.size() + 1 != proxy.poses.size()) {
    const std::string count = proxy_path + " has " + counted(proxy.poses.size() - 1, "example pose");
    if (!manifest.empty()) fail_input(manifest, "lists " + counted(pose_paths.size(), "pose") + "; " + count);
    fail_option("poses", count + "; " + counted(pose_paths.size(), "pose file") + (pose_paths.size() == 1 ? " was" : " were") +
                             " given");
  }
  const LoadedMesh rest = load_mesh(rest_path);
  // Made from another mesh, the proxy would be measured (or drawn) on it without a word.
  check_rest_holds(proxy, rest.mesh, rest_path, "mesh");
  std::vector<TriMesh> meshes{rest.mesh};
  std::vector<TriMesh> poses = load_poses(pose_paths, rest);
  // A proxy made from the manifest calls its poses by the manifest's names, one made from the
  // files (or by an older pose-map) by their stems: either matches.
  const std::vector<std::string> names = pose_names(manifest, pose_paths);
  for (size_t i = 0; i < pose_paths.size(); ++i) {
    meshes.push_back(std::move(poses[i]));
    const std::string& called = proxy.poses[i + 1].name;
    if (called != names[i] && called != stem_of(pose_paths[i]))
      log.warn(pose_paths[i] + ": the proxy calls pose " + std::to_string(i + 1) + " '" + proxy.poses[i + 1].name +
               "'; poses are matched by order");
  }
  return meshes;
}

namespace {

json measurement_json(const std::string& name, const Measurement& m) {
  json j = m.error.to_json();
  j["name"] = name;
  j["coverage"] = m.coverage;
  j["zero_radius"] = m.zero_radius;
  return j;
}

}  // namespace

json proxy_eval_report(const ProxyModel& proxy, const EvalResult& r) {
  json poses = json::array();
  for (size_t i = 0; i < r.poses.size(); ++i) {
    json j = measurement_json(r.poses[i].name, r.pose_measurements[i]);
    j["outside"] = proxy.poses[i].outside.size();
    poses.push_back(j);
  }
  json samples = json::array();
  std::vector<double> medians, maxima;
  for (size_t b = 0; b < r.blend_measurements.size(); ++b) {
    json j = measurement_json("blend-" + std::to_string(b), r.blend_measurements[b]);
    j["weights"] = r.blend_weights[b];
    medians.push_back(r.blend_measurements[b].error.abs.median);
    maxima.push_back(r.blend_measurements[b].error.abs.max);
    samples.push_back(j);
  }
  json blends = {{"count", samples.size()}, {"samples", samples}};
  if (!medians.empty()) {
    std::sort(medians.begin(), medians.end());
    blends["median"] = medians[medians.size() / 2];
    blends["max"] = *std::max_element(maxima.begin(), maxima.end());
  }
  return {{"poses", poses},
          {"blends", blends},
          {"runtime", {{"blend_global_us_median", r.blend_global_us}, {"spheres", proxy.sphere_count()},
                       {"poses", proxy.poses.size()}}}};
}

namespace {

// The pose a .ply of error colours shows: --color-pose, or the rest where it is not given.
int pose_drawn(const EvalToolOptions& opt) { return std::max(opt.color_pose, 0); }

// The proxy at its examples and blends between them, with error colours on request.
void evaluate_examples(const ProxyModel& proxy, const std::string& proxy_path, const std::vector<TriMesh>& meshes,
                       const EvalToolOptions& opt, Log& log, json& report) {
  const std::string ext = lower_extension(opt.colors);
  EvalResult r;
  {
    StageTimer t(log, "evaluate");
    r = about_file(proxy_path, [&] { return evaluate_proxy(proxy, meshes, opt.eval, log); });
  }
  const json measured = proxy_eval_report(proxy, r);
  char line[256];
  const int name_width = pose_name_width(r.poses);
  std::vector<PoseLine> lines;
  for (size_t i = 0; i < r.poses.size(); ++i) {
    const Measurement& m = r.pose_measurements[i];
    std::snprintf(line, sizeof line, " median %.4g p95 %.4g max %.4g coverage %.3f", m.error.abs.median, m.error.abs.p95,
                  m.error.abs.max, m.coverage);
    lines.push_back({padded(r.poses[i].name, name_width) + line, m.error.abs.max});
  }
  print_pose_lines(lines, log, "");
  if (measured["blends"].contains("max")) {
    std::snprintf(line, sizeof line, " median %.4g max %.4g over %d blends", measured["blends"]["median"].get<double>(),
                  measured["blends"]["max"].get<double>(), opt.eval.blends);
    // A skinned proxy's blends of its poses are no motion a host plays: said beside the figure.
    log.info(padded("blends", name_width) + line + (proxy.skin.joints.empty() ? "" : " (a host skins this proxy instead)"));
  }
  if (!opt.colors.empty()) {
    StageTimer t(log, "colors");
    double scale = opt.color_scale;
    if (!(scale > 0))
      for (const Measurement& m : r.pose_measurements) scale = std::max(scale, m.error.abs.max);
    std::vector<PoseError> shown = r.poses;
    write_file_atomic(opt.colors,
                      encode_error_scene(shown, ext, pose_drawn(opt), scale, 1.25 * meshes[0].bounds().sizes().x()));
    report["colors"] = {{"file", opt.colors}, {"scale", scale}};
  }
  report.update(measured);
}

// What the options ask of the proxy, told before the examples are measured, not after.
void check_options_against(const ProxyModel& proxy, const EvalToolOptions& opt) {
  if (!opt.colors.empty() && lower_extension(opt.colors) == ".ply")
    check_pose_number(pose_drawn(opt), proxy.poses.size());
}

}  // namespace

void proxy_eval_files(const std::string& proxy_path, const std::string& rest_path, const std::vector<std::string>& pose_paths,
                      const EvalToolOptions& opt, Log& log, json& report) {
  if (!opt.colors.empty()) {
    const std::string ext = lower_extension(opt.colors);
    if (ext != ".glb" && ext != ".ply") fail_usage(opt.colors, "colours go to .glb or .ply");
    if (opt.color_pose >= 0 && ext != ".ply") fail_usage("--color-pose", "is for a .ply (a .glb holds every pose)");
    if (rest_path.empty()) fail_option("colors", "colours are drawn on the examples: give --rest/--pose or --manifest");
  }
  if (rest_path.empty() && opt.motion.asset.empty())
    fail_option("rest", "give the examples (--rest/--pose or --manifest), a clip (--asset), or both");
  const ProxyModel proxy = read_proxy_file(proxy_path);
  check_spx_pose_count(proxy.poses.size(), proxy_path);  // measured as a host loads it, before the work
  check_options_against(proxy, opt);
  // The clip's asset, opened (and the proxy checked against it) before the examples' work.
  std::unique_ptr<Asset> asset;
  if (!opt.motion.asset.empty()) {
    asset = std::make_unique<Asset>(opt.motion.asset, opt.motion.mesh);
    example_targets(proxy, *asset);
  }
  std::vector<TriMesh> meshes;
  if (!rest_path.empty()) {
    {
      StageTimer t(log, "load");
      meshes = load_pose_meshes(rest_path, pose_paths, proxy, proxy_path, log, opt.motion.manifest);
    }
    evaluate_examples(proxy, proxy_path, meshes, opt, log, report);
    // Blends of a clip's frames are no motion of it: a skinned proxy's figures are its clip's.
    if (!proxy.skin.joints.empty() && opt.motion.asset.empty())
      log.info("a host plays this proxy by its skin, not by blends of its poses: --asset (the rigged asset) "
               "and --animation measure it over the clip as the host skins it");
  }
  if (asset) {
    StageTimer t(log, "motion");
    report["motion"] = about_file(proxy_path, [&] { return proxy_motion_report(proxy, *asset, meshes, opt.motion, log); });
  }
  report["input"] = proxy_path;
  report["sphere_count"] = proxy.sphere_count();
}

}  // namespace spx
