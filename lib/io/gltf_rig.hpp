#pragma once
// An articulated body as binary glTF, the way game assets often ship one: rigid parts, each a
// mesh on its own node, parented to a hierarchy of joint nodes that one clip rotates. Positions
// and keys are single precision, as glTF stores them.
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "mesh/mesh.hpp"

namespace spx {

struct RigJoint {
  std::string name;
  int parent = -1;                  // an earlier joint, or -1 for the root
  Eigen::Vector3d translation;      // from the parent joint, constant
  // Local rotation at each of the clip's key times (one per RigAsset::times).
  std::vector<Eigen::Quaterniond> rotations;
};

struct RigPart {
  std::string name;
  int joint = 0;  // the joint node it hangs from
  TriMesh mesh;   // in that joint's frame
};

struct RigAsset {
  std::string name;  // the scene's root node and the clip
  std::vector<RigJoint> joints;
  std::vector<RigPart> parts;
  std::vector<double> times;  // the clip's key times, ascending, seconds
};

std::string encode_rig_glb(const RigAsset& asset);

}  // namespace spx
