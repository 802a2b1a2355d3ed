#pragma once
// The one rule for a sphere's radius in any pose, the rest included (pose-map's mapping and its
// joint selection alike): min(max radius, exact distance to the pose's mesh and, for an open
// mesh, a bound from the pose's own field across its holes); 0 where the centre is outside, with
// the cause counted for the report.
#include <utility>

#include "core/sphere.hpp"
#include "io/dense_field.hpp"
#include "mesh/mesh_query.hpp"

namespace spx {

struct PoseSolid {
  const MeshQuery* mesh;
  const DenseField* holes;  // null for closed meshes
  double max_radius;
  const DenseField* field = nullptr;  // the pose's own field where kept (floors under radii)

  // Why a radius is 0: the centre is outside, the holes bound it, it is on the surface, or (a
  // skinned sphere, one radius in every pose) it is 0 in another pose.
  enum class Zero : char { none, outside, hole_bound, other, another_pose };
  struct Radius {
    double value = 0;
    Zero zero = Zero::none;
  };

  // The radius at c. `cause`: tell an outside centre from a hole's bound where the radius is 0
  // (asked for the spheres written, not for every candidate); the radius is the same either way.
  Radius radius(const Eigen::Vector3d& c, bool cause = true) const;
  // The sphere at c by this rule, grown to the largest that contains it (grow_inscribed), the
  // holes bounding it too.
  std::pair<Sphere, Zero> grown(const Eigen::Vector3d& c, bool cause = true) const;
  // Distance is 1-Lipschitz: a voxel's depth less its offset to c bounds the depth at c; the
  // best of the 8 voxels around c, less the field's margin. Infinite for a closed mesh.
  double hole_bound(const Eigen::Vector3d& c) const;
  // A floor under radius(c) from the pose's own field (0 without one): the same bound less a
  // whole voxel (the field's distances are within a small fraction of one of the exact ones).
  // A pose whose floor is above a sphere's least radius so far cannot lower it.
  double radius_floor(const Eigen::Vector3d& c) const;
  static constexpr double kFloorMargin = 1.0;  // voxels
};

}  // namespace spx
