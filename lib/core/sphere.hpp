#pragma once
// A sphere (centre and radius) and a set of them: what every stage passes around.
#include <Eigen/Core>
#include <vector>

namespace spx {

struct Sphere {
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  double radius = 0;
};

using SphereSet = std::vector<Sphere>;

}  // namespace spx
