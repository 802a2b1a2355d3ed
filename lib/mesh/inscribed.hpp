#pragma once
// Growing an inscribed sphere to the largest one that contains it.
#include <functional>

#include "core/sphere.hpp"
#include "mesh/mesh_query.hpp"

namespace spx {

// An inscribed sphere at `center` whose radius is the exact distance to the surface touches it
// at the closest point p. The balls tangent at p with centers along the inward normal are
// nested, so moving the center away from p while the distance keeps up with the offset gives a
// larger sphere that still lies inside and contains the first: it covers everything the first
// covers. The offset grows by at most `growth` times the first radius and the radius stays at
// most `max_radius`. `bound(q)`, when given, further limits the radius at q (an open mesh's
// holes). Returns the sphere unchanged where it does not touch the surface (radius below the
// distance) or cannot grow; the radius is always the rule's value at the returned center.
Sphere grow_inscribed(const MeshQuery& mesh, const Sphere& sphere, double max_radius, double growth,
                      const std::function<double(const Eigen::Vector3d&)>& bound = {});

// How far spheres grow by default (the offset at most doubles the radius): enough to reach the
// medial axis from a candidate off it by a voxel or two, little enough that a pose's sphere
// stays on the same part of the body as the rest sphere it came from.
constexpr double kDefaultGrowth = 1.0;

}  // namespace spx
