#pragma once
// Error over a rigged body's motion, measured as hosts run it: the proxy skinned by each frame's
// joint matrices through the runtime header (spx::skin), beside two runtimes a host could use
// instead with the same spheres: each sphere rigid on its heaviest joint (colliders attached to
// bones), and the proxy's examples blended at the weights that best fit the frame's mesh.
#include <array>
#include <functional>
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
  std::vector<Eigen::Matrix4d> joints; // joint matrices in the proxy's joint order
};

// One runtime's spheres against one frame's body.
struct FrameError {
  double median = 0, max = 0;  // |vertex-to-union distance| over the solid's surface vertices
  double overshoot = 0;        // how far the union may poke out: max over spheres of r - depth(centre), >= 0
  size_t outside = 0;          // spheres (radius > 0) whose centre is outside the body
  size_t zero = 0;             // spheres of radius 0
};

enum MotionRuntime { kSkinned = 0, kRigid = 1, kBestBlend = 2, kMotionRuntimes = 3 };
const char* motion_runtime_name(int runtime);

struct MotionRow {
  double time = 0;
  bool seen = false, between = false;
  std::array<FrameError, kMotionRuntimes> error;
  std::vector<float> blend_weights;  // the best-fit weights (empty without examples)
};

struct MotionResult {
  std::vector<MotionRow> rows;
  bool blend = false;   // examples were given: the best-fit blend was measured
  double skin_us = 0;   // median time of one spx::skin of every sphere
};

// `frame(i)` for i < frame_count builds frame i (called from worker threads, once each).
// `examples` are the proxy's poses as meshes on the frames' vertices (rest first), or empty to
// leave out the best-fit blend. Exit 3 when the proxy has no skin or the joints disagree.
MotionResult evaluate_motion(const ProxyModel& proxy, size_t frame_count, const std::function<MotionFrame(size_t)>& frame,
                             const std::vector<TriMesh>& examples, Log& log);

}  // namespace spx
