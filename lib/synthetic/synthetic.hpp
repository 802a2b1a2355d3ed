#pragma once
// Synthetic assets the project generates itself (sample-gen; samples/ runs the chain on them): closed meshes with smooth analytic example
// deformations, so the true map f from rest to each pose is known everywhere (tests use it).
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "io/gltf_morph.hpp"
#include "io/gltf_rig.hpp"
#include "mesh/mesh.hpp"

namespace spx {

struct SampleAsset {
  std::string name;
  TriMesh rest;
  std::vector<std::string> pose_names;
  // The true map f: rest-space point -> its position in pose `pose` (0-based over pose_names).
  std::function<Eigen::Vector3d(size_t pose, const Eigen::Vector3d&)> deform;

  TriMesh pose(size_t index) const;
};

// A closed surface of revolution about z, outward: a pole at (0, 0, bottom), a ring of `sectors`
// vertices at each (r, z) of `profile` (from the bottom up), a pole at (0, 0, top).
TriMesh lathe(const std::vector<std::pair<double, double>>& profile, double bottom, double top, int sectors);

// A car-like body, 5.25 m long (x forward, z up, ground at z = 0), about 1500 triangles;
// poses: front, rear, side, roof crumples.
SampleAsset make_car();
// A barrel 0.72 m tall; poses: dent, squash, top (a dented lid).
SampleAsset make_barrel();

SampleAsset make_sample(const std::string& name);  // "car" or "barrel"

// A walking robot, 1.8 m tall (y up), of 13 open parts (open boxes and tubes, the pelvis inside
// the torso, the upper arms reaching into it) each hung rigidly from one of 13 joints, with a
// 24-key walk: the articulated kind of game asset whose parts are not closed.
RigAsset make_robot();

// The sample as one mesh with its poses as morph targets (named after them).
MorphAsset morph_asset(const SampleAsset& asset);

}  // namespace spx
