#pragma once
// A rigged or morph-target asset (glTF/GLB, FBX, COLLADA, ... through assimp) evaluated into
// vertex positions: the bind pose, one morph target, or a clip at a time. Positions come in the
// file's own vertex layout (every mesh instance's vertices in turn); welding is the caller's.
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "core/json_io.hpp"
#include "mesh/mesh.hpp"

struct aiNode;
struct aiScene;
namespace Assimp {
class Importer;
}

namespace spx {

struct ClipMends;  // mesh/gltf_input.hpp

// One mesh placed by one node of the file's hierarchy.
struct AssetMesh {
  std::string name;  // the mesh's own name ("mesh-<i>" when it has none)
  std::string node;  // the node that places it
  size_t vertices = 0, triangles = 0;
  size_t other_faces = 0;                  // points and lines, not part of the surface
  size_t joints = 0;                       // bones of its skin (0: not skinned)
  std::vector<std::string> morph_targets;  // "target-<i>" when unnamed
  bool used = false;                       // part of the body (--mesh, or every mesh)
};

// A joint of the body's skin: a skin joint of a skinned mesh, or the node that places a mesh
// without a skin (a rigid part, weight 1 on each of its vertices, inverse bind the identity).
// Its matrix in a pose is the node's global transform times the inverse bind, the matrix a
// host computes to skin the mesh: it acts on the positions as the file stores them.
struct AssetJoint {
  std::string name;  // the node's name (with "#2", "#3", ... for a node bound twice)
  int parent = -1;   // the joint of the nearest ancestor node that is one, else -1
  Eigen::Matrix4d inverse_bind = Eigen::Matrix4d::Identity();
};

// An animation clip; times in seconds from the clip's start.
struct AssetClip {
  std::string name;
  double ticks_per_second = 0;
  double end = 0;              // the last key
  std::vector<double> frames;  // every distinct key time, ascending
  size_t node_channels = 0, keys = 0;
  size_t morph_channels = 0;  // those weighing a target of the body's meshes
  // Channels that move no node's transform or morph weights (a material's colour by
  // KHR_animation_pointer), which the poses do not follow: "animations[0].channels[4] (...)".
  std::vector<std::string> passed_over;
};

class Asset {
 public:
  // Reads `path`; `mesh_name` empty takes every mesh as one body, else the meshes (or the
  // node's meshes) of that name. Errors name the file (exit 2/3) or the option (exit 1).
  Asset(const std::string& path, const std::string& mesh_name);
  ~Asset();
  Asset(const Asset&) = delete;
  Asset& operator=(const Asset&) = delete;

  const std::string& path() const { return path_; }
  const std::vector<AssetMesh>& meshes() const { return meshes_; }
  const std::vector<AssetClip>& clips() const { return clips_; }
  // A clip by name, or by index when `which` is a number. Exit 1 naming --animation otherwise.
  size_t find_clip(const std::string& which) const;
  // Each clip's name in messages: its own, or "<index> (unnamed)".
  std::vector<std::string> clip_labels() const;
  // The used meshes' morph targets in file order: each of a mesh's its own entry, those of one
  // name in another mesh matched to them in order (a body split into meshes shares its targets
  // by name; the primitives of one glTF mesh share their targets).
  const std::vector<std::string>& morph_targets() const { return targets_; }

  // The body in the file's vertex layout.
  const std::vector<Eigen::Vector3i>& triangles() const { return triangles_; }
  size_t vertex_count() const { return vertex_count_; }
  // Skinned vertices no joint weighs (they keep their bind position).
  size_t unweighted_vertices() const { return unweighted_; }
  // Polygons that cross themselves, split as fans (at their stored positions).
  const FannedPolygons& fanned() const { return fanned_; }

  // The bind pose: skinned meshes as stored (glTF ignores a skinned mesh's node transform),
  // the others placed by their node; morph weights zero, or with `at_default_weights` the
  // meshes' default ones (glTF's mesh or node `weights`: what a clip that drives no weights
  // plays, so the rest a skin deforms).
  std::vector<Eigen::Vector3d> rest(bool at_default_weights = false) const;
  // The positions as the file stores them (no skin, no node transform, morph weights zero): what
  // the joint matrices act on.
  std::vector<Eigen::Vector3d> stored() const;
  // The rest with morph target `target` (an index into morph_targets()) at weight 1.
  std::vector<Eigen::Vector3d> morph_target(size_t target) const;
  // The rest (node transforms at rest, no clip) with each morph target at its weight in
  // `weights` (one per morph_targets() entry): what a host's blend shapes make of the mesh.
  std::vector<Eigen::Vector3d> morphed(const std::vector<double>& weights) const;
  // The weight clip `clip` gives each morph target at `seconds` (one per morph_targets() entry;
  // the meshes' default weights where it drives none). A target shared by several meshes takes
  // the first one's.
  std::vector<double> morph_weights(size_t clip, double seconds) const;
  // Clip `clip` at `seconds`: node keys interpolated (linear, rotations by slerp), morph weights
  // the clip drives (the meshes' default ones where it drives none), then linear blend skinning
  // with each joint's global transform times its inverse bind matrix.
  std::vector<Eigen::Vector3d> at_time(size_t clip, double seconds) const;

  // The body's joints, and per file vertex its (joint, weight) pairs, weights summing to 1
  // (empty for skinned vertices no joint weighs).
  const std::vector<AssetJoint>& joints() const { return joints_; }
  std::vector<std::vector<std::pair<int, double>>> vertex_joints() const;
  // The joint of each name (a proxy's skin joints), as a host binds a skeleton by name. Exit 2
  // naming the file where one is missing: not the asset the proxy was made from.
  std::vector<size_t> joints_named(const std::vector<std::string>& names) const;
  // Every joint's matrix at rest, and in clip `clip` at `seconds`.
  std::vector<Eigen::Matrix4d> rest_joint_matrices() const;
  std::vector<Eigen::Matrix4d> joint_matrices(size_t clip, double seconds) const;

  // What the file holds, for the report.
  json inventory() const;

 private:
  struct Instance;
  struct Pose;
  void list_meshes(const std::vector<std::pair<const aiNode*, unsigned>>& placed, const std::string& wanted);
  void use_meshes(const std::vector<std::pair<const aiNode*, unsigned>>& placed);
  void read_clips(const ClipMends& mends);
  int joint_of(const aiNode* node, const Eigen::Matrix4d& inverse_bind);
  void link_joint_parents();
  Pose clip_pose(size_t clip, double seconds) const;
  std::vector<Eigen::Matrix4d> joint_matrices(const Pose& pose) const;
  std::vector<Eigen::Vector3d> evaluate(const Pose& pose) const;

  std::string path_;
  std::unique_ptr<Assimp::Importer> importer_;
  const aiScene* scene_ = nullptr;
  FannedPolygons fanned_;
  std::vector<AssetMesh> meshes_;
  std::vector<Instance> instances_;  // the used meshes, in file order
  std::vector<AssetClip> clips_;
  std::vector<std::string> targets_;
  std::vector<AssetJoint> joints_;
  std::vector<const aiNode*> joint_nodes_;  // per joint
  std::vector<Eigen::Vector3i> triangles_;
  size_t vertex_count_ = 0, unweighted_ = 0;
};

// The body welded by position (as pose-extract writes it; extract/welded_body.cpp): file vertex -> welded vertex, and the
// rest's triangles on welded vertices, those that repeat another's read once (`repeated`: two
// instances of a skinned mesh, which its skin puts in one place, or faces doubled; and a closed
// part given both ways, its inner side dropped). The rest at the default morph weights where
// asked (a clip's rest), else at zero.
struct WeldedBody {
  std::vector<int> weld;
  TriMesh rest;
  RepeatedTriangles repeated;
};
WeldedBody weld_body(const Asset& asset, bool at_default_weights = false);
// Per welded vertex its first file vertex: the one whose position (welded_pose) and weights
// (skin.json, the page) it takes.
std::vector<size_t> first_file_vertices(const WeldedBody& body);

// A joint whose rest matrix is flat (a node scaled to 0, or an inverse bind matrix of zeros)
// collapses the vertices it alone weighs: the rest would be another body (the part gone, its
// vertices welded into one, and each pose's parted again). Exit 2 naming `input` and the joints.
void check_rest_not_collapsed(const Asset& asset, const std::string& input);
// Every rest vertex finite, or exit 2 naming `input` and the first that is not.
void check_rest_finite(const WeldedBody& body, const std::string& input);

// A pose on the welded vertices (each takes its first file vertex's position); `opened` counts
// rest-welded points that part in this pose. A vertex that is not finite fails naming `input`.
TriMesh welded_pose(const WeldedBody& body, const std::vector<Eigen::Vector3d>& file_positions, double tolerance,
                    size_t& opened, const std::string& what, const std::string& input);

}  // namespace spx
