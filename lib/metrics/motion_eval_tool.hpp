#pragma once
// proxy-eval --asset A.glb --animation N: a rigged body's proxy measured over a clip of its asset
// (metrics/motion_eval.hpp), every frame asked for and half-way between them.
#include <string>
#include <vector>

#include "core/json_io.hpp"
#include "core/log.hpp"
#include "core/tolerance.hpp"
#include "io/proxy_file.hpp"
#include "mesh/mesh.hpp"

namespace spx {

struct MotionToolOptions {
  std::string asset;           // the rigged asset (glTF, FBX, ... through assimp)
  std::string mesh;            // one mesh (or node) of it by name, as pose-extract --mesh
  std::string animation;       // clip by name or index
  int every = 1;               // every Nth frame of the clip (its distinct key times)
  std::vector<double> times;   // or these times, in seconds
  int between = 1;             // times evenly between consecutive ones (1: half-way; 0: none)
  std::string manifest;        // pose-extract's poses.json the proxy came from: which frames it saw
  std::string chart;           // OUT.svg: error over time (the paper's Figure 5)
  Tolerance tolerance;         // the target the errors are compared with (ratios in the report)
};

// A proxy a clip can be measured on, or spx::Error (exit 1, the option "asset"): it has a skin.
void check_has_skin(const ProxyModel& proxy);

// Measures `proxy` over the clip (checked by check_has_skin first); `examples` (rest first, on the asset's welded vertices, or
// empty) give the best-fit blend beside it. Returns the report's "motion" object.
json proxy_motion_report(const ProxyModel& proxy, const std::vector<TriMesh>& examples, const MotionToolOptions& options,
                         Log& log);

}  // namespace spx
