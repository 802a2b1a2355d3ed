#pragma once
// Error over a body's motion, measured as hosts run it. A rigged body's proxy: skinned by each
// frame's joint matrices through the runtime header (spx::skin), beside two runtimes a host could
// use instead with the same spheres: each sphere rigid on its heaviest joint (colliders attached
// to bones), and the proxy's examples blended at the weights that best fit the frame's mesh. A
// morph-target body's proxy: blended by each frame's morph weights (spx::blend_morph), beside the
// global blend at those weights (the rest at 1 less their sum) and the best-fit blend.
#include <array>
#include <functional>
#include <string>
#include <vector>

#include "core/log.hpp"
#include "io/proxy_file.hpp"
#include "mesh/mesh.hpp"

namespace spx {

// One frame of the motion, from the caller (an asset's clip).
struct MotionFrame {
  double time = 0;
  bool seen = false;                   // one of the frames the proxy was made from
  bool between = false;                // half-way between two frames asked for
  TriMesh mesh;                        // the body then, on the examples' vertices
  std::vector<Eigen::Matrix4d> joints; // a rigged body: joint matrices in the proxy's joint order
  std::vector<float> morph_weights;    // a morph-target body: one per example after the rest
};

// One runtime's spheres against one frame's body.
struct FrameError {
  double median = 0, max = 0;  // |vertex-to-union distance| over the solid's surface vertices
  double overshoot = 0;        // how far the union may poke out: max over spheres of r - depth(centre), >= 0
  size_t outside = 0;          // spheres (radius > 0) whose centre is outside the body
  size_t zero = 0;             // spheres of radius 0
};

enum MotionRuntime { kSkinned = 0, kRigid = 1, kBestBlend = 2, kMorph = 3, kGlobal = 4, kMotionRuntimes = 5 };
const char* motion_runtime_name(int runtime);

struct MotionRow {
  double time = 0;
  bool seen = false, between = false;
  std::array<FrameError, kMotionRuntimes> error;
  std::vector<float> blend_weights;  // the best-fit weights (empty without examples)
};

struct MotionResult {
  std::vector<MotionRow> rows;
  // Those measured, the host's first: kSkinned, kRigid (a skin) or kMorph, kGlobal (none), then
  // kBestBlend where examples were given.
  std::vector<int> runtimes;
  double host_us = 0;  // median time of the host's runtime (spx::skin or spx::blend_morph) on every sphere
  bool measured(int runtime) const;
};

// `frame(i)` for i < frame_count builds frame i (called from worker threads, once each).
// `examples` are the proxy's poses as meshes on the frames' vertices (rest first), or empty to
// leave out the best-fit blend. A proxy with a skin is skinned by the frames' joint matrices,
// one without is blended by their morph weights. Exit 3 when the frames' joints or weights do
// not fit the proxy; exit 2 naming `source` (the frames' asset) where the runtime's spheres are
// not finite at a frame.
MotionResult evaluate_motion(const ProxyModel& proxy, size_t frame_count, const std::function<MotionFrame(size_t)>& frame,
                             const std::vector<TriMesh>& examples, Log& log, const std::string& source = "");

}  // namespace spx
