#pragma once
// proxy-eval: how wrong a proxy is, as the paper measures it (vertex-to-union distance per pose,
// its Figures 4-6), plus coverage of the interior and the blends a host shows at runtime.
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/log.hpp"
#include "mesh/mesh.hpp"
#include "mesh/union_distance.hpp"
#include "io/proxy_file.hpp"

namespace spx {

// Fraction of the mesh's interior (winding number > 1/2) inside the union, sampled at the
// centers of a grid with `samples` cells along the longest side of the bounding box.
double union_coverage(const TriMesh& mesh, const SphereSet& spheres, int samples = 48);

struct SurfaceError {
  ErrorStats abs;                 // of |distance|
  double signed_median = 0, signed_min = 0, signed_max = 0;
  double outside_fraction = 0;    // vertices outside the union (positive distance)
  nlohmann::json to_json() const;
};
SurfaceError surface_error(const std::vector<double>& signed_distance);

struct EvalOptions {
  int blends = 8;            // weight vectors to try between examples (at most kMaxBlends)
  unsigned seed = 1;         // for the random convex combinations
  int coverage_samples = 48;
};

// One mesh and its spheres measured: the error, the share of the interior covered, the spheres
// of radius 0.
struct Measurement {
  SurfaceError error;
  double coverage = 0;
  size_t zero_radius = 0;
};

struct EvalResult {
  std::vector<PoseError> poses;   // rest first, then the examples
  std::vector<Measurement> pose_measurements;
  // Blend b ("blend-b"): its measurement and weights. Its mesh and spheres are not kept: a run of
  // many blends would hold a mesh for each.
  std::vector<Measurement> blend_measurements;
  std::vector<std::vector<float>> blend_weights;
  double blend_global_us = 0;     // the median time of one global blend through the runtime
};

// `meshes` are M_0..M_e in the proxy's pose order. Blends go through the runtime header,
// exactly as a host computes them.
EvalResult evaluate_proxy(const ProxyModel& proxy, const std::vector<TriMesh>& meshes, const EvalOptions& options,
                          Log& log = Log::silent());

// The median over 31 runs of one call's time in microseconds (each run the mean of 20 calls): how
// the runtime's per-frame costs are reported.
double median_call_us(const std::function<void()>& call);

// More blends than this are refused: each is a whole measurement, and their weights are listed.
constexpr int kMaxBlends = 100000;

// Weight vectors over `poses` examples: midpoints of pairs first, then seeded random convex
// combinations; `count` in all.
std::vector<std::vector<float>> blend_weights(size_t poses, int count, unsigned seed);

}  // namespace spx
