#pragma once
// The proxy's spheres as colliders engines read from glTF: one node per sphere (its centre the
// node's translation, as a sphere shape is centred on its node) carrying a KHR_physics_rigid_bodies
// collider on a KHR_implicit_shapes sphere and the same as OMI_physics_body on an OMI_physics_shape
// sphere (what Godot 4 imports), under a kinematic body. The extensions are listed in
// extensionsUsed only, so a reader without them still opens the file.
#include <string>
#include <vector>

#include "core/json_io.hpp"
#include "core/gltf_file.hpp"
#include "io/proxy_file.hpp"

namespace spx {

class Asset;

struct PhysicsGltf {
  GltfFile file;
  size_t colliders = 0;
  std::vector<int> zero_radius;  // spheres left out (radius 0 at rest)
  json attachment;               // a skinned proxy in its asset: the joints the spheres hang from
  double diagonal = 0;           // with an asset: its rest's bounding-box diagonal
};

// The rest pose alone: a body node with a collider node per sphere of pose 0.
PhysicsGltf physics_gltf(const ProxyModel& proxy);

// Into `asset` (read from the file `rig` was read from), which keeps its meshes, skins and clips:
// a proxy with a skin has each sphere parented to its heaviest joint's node (its centre in that
// joint's frame, so a clip moves it); one without a skin gets a body node at the scene's root.
// Exit 2 naming the asset when its rest does not hold the proxy's rest spheres, it lacks a joint
// the skin names, or it already holds a proxy's colliders (this function's own nodes).
PhysicsGltf physics_gltf(const ProxyModel& proxy, GltfFile asset, const Asset& rig);

// A skinned proxy's spheres rigid on their heaviest joints against the skinned runtime, over
// clip `clip` of `rig` at its key times: how far the centres stray, in parts of `diagonal`.
json rigid_attachment_offsets(const ProxyModel& proxy, const Asset& rig, size_t clip, double diagonal);

}  // namespace spx
