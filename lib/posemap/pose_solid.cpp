#include "posemap/pose_solid.hpp"

#include <algorithm>
#include <functional>
#include <limits>

#include "core/tolerance.hpp"
#include "mesh/inscribed.hpp"

namespace spx {

PoseSolid::Radius PoseSolid::radius_at(const Eigen::Vector3d& c, bool cause, bool trust_floor,
                                       ClosestPoint* closest) const {
  // The field's bound first: it is cheap, and where it is 0 so is the radius. Where it is
  // positive (an open mesh) it already puts c inside: some voxel's depth exceeds its offset to c;
  // so does a floor past a whole voxel (the field's distances are within a fraction of one).
  const double bound = hole_bound(c);
  if (!(bound > 0) && !cause) return {0, Zero::hole_bound};
  const bool surely_inside =
      (holes && bound > 0) || (trust_floor && field && radius_floor(c) > field->shape.voxel_size);
  if (!surely_inside && !mesh->inside(c)) return {0, Zero::outside};
  if (closest) *closest = mesh->closest(c);
  const double exact = std::min(max_radius, closest ? closest->tree_distance : mesh->distance(c));
  const double r = std::min(exact, bound);
  if (r > 0) return {r, Zero::none};
  return {0, exact > 0 ? Zero::hole_bound : Zero::other};
}

std::pair<Sphere, PoseSolid::Zero> PoseSolid::grown(const Eigen::Vector3d& c, bool cause) const {
  ClosestPoint closest;
  const Radius at = radius_at(c, cause, true, &closest);
  if (at.zero != Zero::none) return {{c, 0}, at.zero};
  std::function<double(const Eigen::Vector3d&)> bound;
  if (holes) bound = [this](const Eigen::Vector3d& q) { return hole_bound(q); };
  return {grow_inscribed(*mesh, {c, at.value}, closest, max_radius, kDefaultGrowth, bound), Zero::none};
}


bool PoseSolid::surely_at_least(const Eigen::Vector3d& c, double r) const {
  if (!shape || !(r > 0) || r > max_radius || holes || shape->nearer_than(c, r)) return false;
  // Nothing nearer than r: c is as much inside as the whole ball; the floor (as radius() trusts
  // it) or the ray count says which.
  return (field && radius_floor(c) > field->shape.voxel_size) || shape->inside(c);
}

double PoseSolid::hole_bound(const Eigen::Vector3d& c) const {
  if (!holes) return std::numeric_limits<double>::infinity();
  return std::max(0.0, depth_bound(*holes, c) - kFieldMargin * holes->shape.voxel_size);
}

double PoseSolid::radius_floor(const Eigen::Vector3d& c) const {
  if (!field) return 0;
  // Across an open mesh's holes the radius is also at most the hole bound.
  return std::clamp(std::min(depth_bound(*field, c), hole_bound(c)), 0.0, max_radius);
}

}  // namespace spx
