#pragma once
// A mesh with morph targets (blend shapes) as binary glTF: how the samples ship example
// deformations the way artists keep them. Positions are single precision, as glTF stores them.
#include <string>
#include <vector>

#include "mesh/mesh.hpp"

namespace spx {

struct MorphAsset {
  std::string name;                                   // the mesh, its node and its clip
  TriMesh base;                                       // the rest shape
  std::vector<std::string> target_names;              // written as the mesh's extras.targetNames
  std::vector<std::vector<Eigen::Vector3d>> targets;  // absolute positions, one per base vertex
};

// One mesh, one node and one clip named after the asset. The clip drives the weights: all zero
// at t = 0 s, then weight 1 on target k alone at t = k + 1 s, then with two targets or more every
// target at 1 at once, one second after the last (linear in between).
std::string encode_morph_glb(const MorphAsset& asset);

// The positions a glTF reader gets back: the single-precision base, and the base plus the
// stored single-precision displacement for a target (computed in single precision, as
// readers add them).
std::vector<Eigen::Vector3d> stored_base(const MorphAsset& asset);
std::vector<Eigen::Vector3d> stored_target(const MorphAsset& asset, size_t target);

}  // namespace spx
