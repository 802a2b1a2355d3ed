#pragma once
// The one rule for a sphere's radius in any pose, the rest included (pose-map's mapping and its
// joint selection alike): min(max radius, exact distance to the pose's mesh and, for an open
// mesh, a bound from the pose's own field across its holes); 0 where the centre is outside, with
// the cause counted for the report.
#include <utility>

#include "core/sphere.hpp"
#include "io/dense_field.hpp"
#include "mesh/deforming_query.hpp"
#include "mesh/mesh_query.hpp"

namespace spx {

struct PoseSolid {
  const MeshQuery* mesh;
  const DenseField* holes;  // null for closed meshes
  double max_radius;
  const DepthField* field = nullptr;  // the pose's own field's depths where kept (floors under radii)
  const DeformingQuery::Shape* shape = nullptr;  // a closed mesh's refitted hierarchy, where kept

  // Why a radius is 0: the centre is outside, the holes bound it, it is on the surface, or (a
  // skinned sphere, one radius in every pose) it is 0 in another pose.
  enum class Zero : char { none, outside, hole_bound, other, another_pose };
  struct Radius {
    double value = 0;
    Zero zero = Zero::none;
  };

  // The radius at c. `cause`: tell an outside centre from a hole's bound where the radius is 0
  // (asked for the spheres written, not for every candidate); the radius is the same either way.
  // A floor (below) past a whole voxel is taken to put c inside without a winding number; else
  // inside is the query's (pose-map tells a closed pose's query by its `shape`'s ray count).
  // `closest`, where given, gets mesh->closest(c) where the radius asked it (a positive radius
  // did): the same radius, one query for a caller that needs both.
  Radius radius(const Eigen::Vector3d& c, bool cause = true, ClosestPoint* closest = nullptr) const {
    return radius_at(c, cause, true, closest);
  }
  // The same with no floor trusted: what a skinned sphere's one radius is checked against.
  Radius exact_radius(const Eigen::Vector3d& c, bool cause = true) const { return radius_at(c, cause, false); }
  // The sphere at c by this rule, grown to the largest that contains it (grow_inscribed), the
  // holes bounding it too.
  std::pair<Sphere, Zero> grown(const Eigen::Vector3d& c, bool cause = true) const;
  // Distance is 1-Lipschitz: a voxel's depth less its offset to c bounds the depth at c; the
  // best of the 8 voxels around c, less the field's margin. Infinite for a closed mesh.
  double hole_bound(const Eigen::Vector3d& c) const;
  // A floor under radius(c) from the pose's own field (0 without one): the same bound as
  // hole_bound's, with no margin. The field's distances are to some triangle, so never below
  // the exact ones and very nearly equal (up to 0.37 voxel above over the elephant's walk): this
  // orders and skips the poses a sphere's one radius asks (a pose whose floor is above the least
  // radius so far is skipped), and every one radius that counts is then checked exactly.
  double radius_floor(const Eigen::Vector3d& c) const;
  // Whether radius(c, false) is surely at least r, told without an exact query where it can be:
  // no point of the surface nearer than r (the refitted hierarchy's bounded search, which skips
  // most boxes) and c inside (by the floor, as radius() trusts it, or by the shape's ray count).
  // False: ask radius(). Needs `shape`.
  bool surely_at_least(const Eigen::Vector3d& c, double r) const;

 private:
  // `closest`: where given, the distance comes from mesh->closest(c), left there (grown() grows
  // from it), instead of mesh->distance(c): the same value, one query for both.
  Radius radius_at(const Eigen::Vector3d& c, bool cause, bool trust_floor, ClosestPoint* closest = nullptr) const;
};

}  // namespace spx
