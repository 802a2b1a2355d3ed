#pragma once
#include <Eigen/Core>
#include <vector>

namespace spx {

struct Sphere {
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  double radius = 0;
};

using SphereSet = std::vector<Sphere>;

}  // namespace spx
