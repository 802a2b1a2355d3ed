#pragma once
// proxy-eval --asset A.glb --animation N: a rigged body's proxy, or a morph-target body's,
// measured over a clip of its asset (metrics/motion_eval.hpp), every frame asked for and half-way
// between them.
#include <string>
#include <vector>

#include "core/json_io.hpp"
#include "core/log.hpp"
#include "core/tolerance.hpp"
#include "io/proxy_file.hpp"
#include "mesh/mesh.hpp"

namespace spx {

class Asset;

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

// A proxy without a skin is measured over a clip by its morph weights: its examples after the
// rest are the asset's morph targets of their names (pose-extract --morph-targets names them so),
// one name taken as often as the asset has it, in order. Returns each example's target (empty
// for a proxy with a skin), or spx::Error (exit 1, the option "asset") naming an example that is
// none.
std::vector<size_t> example_targets(const ProxyModel& proxy, const Asset& asset);

// Measures `proxy` over the clip of `asset` (opened with options.mesh); `examples` (rest first,
// on the asset's welded vertices, or empty) give the best-fit blend beside it. Returns the
// report's "motion" object.
json proxy_motion_report(const ProxyModel& proxy, const Asset& asset, const std::vector<TriMesh>& examples,
                         const MotionToolOptions& options, Log& log);

}  // namespace spx
