#pragma once
// The character host: a rigged body plays its clip in Bullet while objects fall on it. The host
// does what an engine does each frame: its animation system evaluates the clip into joint
// matrices (here the asset read through assimp, as pose-extract reads it), the skin runtime
// moves the proxy's spheres with the same matrices (spx::bullet::skin into a SphereSetShape on a
// kinematic body), then the world steps. Every step is timed, and where the falling objects
// touch the body is checked against the body's own skinned mesh at that frame.
#include <cstdint>
#include <string>
#include <vector>

#include "spx_runtime.h"

namespace spx {
class Asset;
}

namespace spx::character {

struct SceneOptions {
  size_t clip = 0;             // the asset's clip to play (looped)
  double seconds = 10;         // simulated time
  double dt = 1.0 / 60;        // one Bullet step per frame
  double body_height = 3;      // m: the asset's units are scaled so the body is this tall
  int objects = 40;            // boxes and balls dropped on the body, one after another
  double drop_every = 0.2;     // s between drops
  uint32_t seed = 1;           // where they are dropped
  int check_every = 10;        // frames between contact checks against the skinned mesh (0: none)
};

struct RunStats {
  int frames = 0;
  double clip_seconds = 0;
  double animate_ms = 0, skin_ms = 0, step_ms = 0;  // per frame, the median
  uint64_t body_contacts = 0;       // contact points between the body and the objects, summed over frames
  int frames_with_contact = 0;
  int objects_dropped = 0, objects_on_body = 0, objects_fell_off = 0;
  // Contact points checked against the skinned mesh: how far each lies from its surface (the
  // spheres sit inside the body, so a contact on them is at most the proxy's error away).
  uint64_t contacts_checked = 0;
  double contact_to_mesh_median = 0, contact_to_mesh_max = 0;  // m
  int zero_radius_spheres = 0;      // at the last frame
};

// Plays `asset`'s clip with `proxy` (a .spx with a skin whose joints are the asset's) as the
// body's collision shape. Throws spx::Error naming what does not match.
RunStats run_scene(const Asset& asset, const Proxy& proxy, const SceneOptions& options);

}  // namespace spx::character
