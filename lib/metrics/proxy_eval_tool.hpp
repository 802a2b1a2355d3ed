#pragma once
// proxy-eval, the tool: a proxy measured against its meshes (per pose, blends between them),
// with error colours on request.
#include <string>
#include <vector>

#include "core/json_io.hpp"
#include "core/log.hpp"
#include "metrics/motion_eval_tool.hpp"
#include "metrics/proxy_eval.hpp"

namespace spx {

struct EvalToolOptions {
  EvalOptions eval;
  std::string colors;      // OUT.ply | OUT.glb: per-vertex error colours
  int color_pose = -1;     // .ply: the pose drawn (-1: not given, the rest)
  double color_scale = 0;  // error shown as full red; 0: the largest max error over the poses
  MotionToolOptions motion;  // --asset: over a clip (a rigged body's proxy)
};

// Loads M_0..M_e checked against each other and against the proxy: its pose count (a count
// `manifest`, when they came from one, lists) and its rest spheres, whose centres lie inside the
// rest mesh it was made from.
std::vector<TriMesh> load_pose_meshes(const std::string& rest, const std::vector<std::string>& poses, const ProxyModel& proxy,
                                      const std::string& proxy_path, Log& log, const std::string& manifest = "");

// proxy-eval's report of `r`: per pose and per blend the error, coverage and zero radii, the
// blends' median and max, the runtime's blend time.
json proxy_eval_report(const ProxyModel& proxy, const EvalResult& r);

// proxy-eval IN.proxy.json [--rest REST --pose P...] [--asset A --animation N] [--blends N] [--colors OUT]:
// the examples when given (rest empty: none), the clip when an asset is.
void proxy_eval_files(const std::string& proxy_path, const std::string& rest, const std::vector<std::string>& poses,
                      const EvalToolOptions& options, Log& log, json& report);

}  // namespace spx
