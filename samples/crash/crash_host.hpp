#pragma once
// The crash host: the paper's scene (cars launched off ramps into each other) in Bullet, with
// example-based plastic deformation in the spirit of Jones et al. 2016. Every car keeps blend
// weights per blend site; strong collision impulses move the weights of the sites near the
// contact toward the example whose dent matches the impact, and the car's collision shape is
// re-blended from them:
//   - proxy collision: the runtime header's local blend, written into a btCompoundShape of
//     btSphereShape children;
//   - the baseline: the car mesh's vertices blended with the same weights, in a
//     btGImpactMeshShape refitted after each update.
#include <cstdint>
#include <string>
#include <vector>

#include "mesh/mesh.hpp"
#include "spx_runtime.h"

namespace spx::crash {

// Where and which way an example pose dents the car (rest frame): the displacement-weighted
// centre of the moved vertices and the mean direction they move in.
struct Dent {
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();
};

// The example pose (1-based, as in the proxy) whose dent best matches a push `direction`
// at `point` (both in the rest frame), or 0 when no dent points along the push.
int match_dent(const std::vector<Dent>& dents, const Eigen::Vector3d& point, const Eigen::Vector3d& direction,
               double length_scale);

// Everything the cars of one configuration share.
struct CarAsset {
  std::string name;               // configuration name ("compound-320", "triangle-mesh")
  bool spheres = true;            // collide with the proxy (else the triangle mesh)
  bool sphere_set = false;        // proxies as spx::bullet sphere sets: their algorithms against
                                  // the ground, the ramps and each other, not Bullet's compound ones
  const Proxy* proxy = nullptr;   // blend sites (and spheres when `spheres`)
  TriMesh rest;                   // M_0, mesh frame
  std::vector<TriMesh> poses;     // M_0..M_e, the proxy's pose order
  Eigen::Vector3d com = Eigen::Vector3d::Zero();  // volume centroid = body frame origin
  std::vector<uint32_t> vertex_site;              // nearest blend site of each vertex at rest
  std::vector<Dent> dents;                        // per pose; dents[0] unused
  double mass = 1200;                             // kg
  Eigen::Vector3d inertia = Eigen::Vector3d::Zero();  // principal moments (box of the bounds)
  double length = 0;                              // longest side, for dent matching

  size_t sphere_count() const { return spheres ? proxy->sphere_count() : 0; }
};

// Checks that `poses` (M_0..M_e) line up with `proxy`, computes sites, dents, mass properties.
// Throws spx::Error naming the problem.
CarAsset make_car_asset(std::string name, bool spheres, const Proxy& proxy, const std::vector<TriMesh>& poses);

struct SceneOptions {
  int cars = 8;
  double seconds = 10;
  double dt = 1.0 / 60;          // one Bullet substep per frame
  double speed_scale = 1;        // launch speed multiplier (stability runs)
  uint32_t seed = 1;             // lane offsets, yaw and speed jitter (each seed is its own crash)
  double impulse_threshold = 2500;  // N*s summed over one contact pair in one step
  double impulse_scale = 20000;     // N*s above the threshold for a full step toward the example
  double max_step = 0.5;            // cap on how far one step moves a site's weights
  double dent_radius = 1.4;         // m: sites within this distance of the contact are dented
  bool monitor = false;             // error, tunnelling, penetration, energy (never timed)
  int sample_every = 6;             // steps between error samples when monitoring
};

// One car's error over time (Figure 5): vertex-to-union distance of its deformed mesh.
struct ErrorTrace {
  std::vector<double> median, max;
};

struct RunStats {
  int steps = 0;
  double sim_ms = 0;       // inside stepSimulation
  double deform_ms = 0;    // impulse rule, re-blends and shape updates
  double total_ms() const { return sim_ms + deform_ms; }
  uint64_t contacts = 0;        // contact points, summed over steps
  uint64_t reblends = 0;        // car shape updates
  uint64_t state_hash = 0;      // final transforms and weights (repeatability)
  double max_weight_moved = 0;  // largest share any site gave away from the rest pose
  double simplex_error = 0;     // largest |sum - 1| or negative part of any site's weights

  // Monitored runs only.
  std::vector<double> sample_times;
  std::vector<ErrorTrace> error;             // per car (proxy collision only)
  std::vector<std::vector<Eigen::Vector3d>> path;  // per car: centre of mass at the sample times
  int ground_tunnels = 0;                    // cars whose centre of mass fell below the ground
  int car_tunnels = 0;                       // car pairs with a centre of mass inside the other car
  double max_contact_penetration = 0;        // m, deepest contact Bullet reported
  double max_ground_penetration = 0;         // m, deepest car mesh vertex below the ground
  double max_energy_ratio = 0;               // max over time of energy / initial energy
  bool energy_finite = true;
  bool energy_blew_up() const { return !energy_finite || max_energy_ratio > 1.5; }
};

RunStats run_scene(const CarAsset& asset, const SceneOptions& options);

}  // namespace spx::crash
