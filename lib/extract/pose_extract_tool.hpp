#pragma once
// pose-extract: the rest mesh and example poses out of a rigged or morph-target asset, as OBJ
// files sharing one welded topology plus a poses.json manifest (io/pose_manifest.hpp).
#include <string>
#include <vector>

#include "core/json_io.hpp"
#include "core/log.hpp"
#include "mesh/mesh.hpp"

namespace spx {

struct PoseExtractOptions {
  std::string mesh;            // one mesh (or node) by name; empty: every mesh as one body
  bool morph_targets = false;  // one pose per morph target
  std::string animation;       // a clip by name or index: poses by linear blend skinning
  std::vector<int> frames;     // frames of the clip (its distinct key times), by index
  std::vector<double> times;   // times in seconds
  int every = 0;               // every Nth frame (default: every frame)
  int select = 0;              // keep the K frames that best span the clip's deformation
};

// Farthest-point sampling: `k` of `poses`, the first the farthest from `rest`, each next the
// farthest from all chosen so far (and the rest); distances are RMS vertex distances, ties go
// to the earlier pose. Returned in ascending order.
std::vector<size_t> farthest_poses(const std::vector<Eigen::Vector3d>& rest,
                                   const std::vector<std::vector<Eigen::Vector3f>>& poses, size_t k);
double rms_distance(const std::vector<Eigen::Vector3f>& a, const std::vector<Eigen::Vector3f>& b);

// pose-extract IN -o DIR: DIR/rest.obj, one OBJ per pose, DIR/poses.json (written last).
void pose_extract_files(const std::string& input, const std::string& dir, const PoseExtractOptions& options, Log& log,
                        json& report);

}  // namespace spx
