#pragma once
// skin.json: the rig a clip's poses came from, written by pose-extract beside poses.json and
// read by pose-map --manifest (schemas/skin.schema.json). The joints in the skin's order with
// their parents and inverse bind matrices, each welded rest vertex's (joint, weight) pairs, and
// every joint's matrix (global transform x inverse bind) at rest and in each pose. Matrices act
// on positions as the asset stores them (glTF POSITION, the host's mesh space) and carry them
// to where pose-extract put the rest and the poses, so the rest's matrices are what maps the
// host's space to the tools'.
#include <Eigen/Core>
#include <string>
#include <utility>
#include <vector>

#include "core/json_io.hpp"

namespace spx {

struct SkinJoint {
  std::string name;
  int parent = -1;
  Eigen::Matrix4d inverse_bind = Eigen::Matrix4d::Identity();
};

using JointWeights = std::vector<std::pair<int, double>>;  // (joint, weight), weights summing to 1
using JointMatrices = std::vector<Eigen::Matrix4d>;         // one per joint

struct SkinPose {
  std::string name;  // as in poses.json
  JointMatrices matrices;
};

// The clip the poses came from, sampled densely (every key, and between keys half-way and at
// least 60 times a second): what keeps a skinned sphere's one radius over the whole motion, not
// only at the poses.
struct SkinClip {
  std::string name;
  std::vector<double> times;          // seconds
  std::vector<JointMatrices> matrices;  // per time
  bool empty() const { return times.empty(); }
};

struct SkinFile {
  std::vector<SkinJoint> joints;
  // Per welded rest vertex: where it is at rest (what pins the weights to a mesh read back in any
  // vertex order) and its weights (empty: no joint weighs it).
  std::vector<Eigen::Vector3d> vertex_positions;
  std::vector<JointWeights> vertex_weights;
  JointMatrices rest;
  std::vector<SkinPose> poses;  // in poses.json's order
  size_t morph_channels = 0;    // the clip also drives morph weights, which a skin cannot follow
  SkinClip clip;                // optional ("clip")
};

// Exit 2 naming `path` and `field` unless following `parents` (one per joint: -1 for a root, else
// another joint, as the readers check each) from every joint reaches a root, as the runtime's
// loader asks of a .spx: a host walks a joint's parents to the root, which a cycle never reaches.
void require_joint_tree(const std::vector<int>& parents, const std::string& field, const std::string& path);

json skin_to_json(const SkinFile& skin);
// Exit 2 naming `path` and the field when the document is not a valid skin: joint indices out
// of range, parents in a cycle, weights or matrices not finite, a matrix count other than the
// joint count.
SkinFile read_skin_file(const std::string& path);
// The same from a parsed document (`path` names it in errors).
SkinFile skin_from_json(const json& j, const std::string& path);

// The skin's weights for each of `vertices` (a rest mesh as a tool loaded it, in its own order):
// the weights of the skin's vertex within `tolerance` of it. Exit 2 naming `path` when a vertex
// has none (the skin is another mesh's).
std::vector<JointWeights> weights_for_vertices(const SkinFile& skin, const std::vector<Eigen::Vector3d>& vertices,
                                               double tolerance, const std::string& path);

// The weights of a mesh split at its edges' midpoints (split_at_midpoints' `ends`): each added
// vertex weighed by its two ends half and half, appended to `weights` (the mesh's before the
// split, one list per vertex). Linear skinning then moves a midpoint as the blend of its ends'
// joint matrices, as it does any point of a triangle between its corners.
void append_midpoint_weights(std::vector<JointWeights>& weights, const std::vector<std::pair<int, int>>& ends);

}  // namespace spx
