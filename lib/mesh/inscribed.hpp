#pragma once
// Growing an inscribed sphere to the largest one that contains it.
#include <functional>
#include <vector>

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
// The same given `closest`, mesh.closest(sphere.center), which the caller asked already.
Sphere grow_inscribed(const MeshQuery& mesh, const Sphere& sphere, const ClosestPoint& closest, double max_radius,
                      double growth, const std::function<double(const Eigen::Vector3d&)>& bound = {});
// A ball that holds what grow_inscribed returns for these arguments, whatever `bound`: the
// grown balls are tangent at the closest point with centres along its normal, so each lies in
// the largest the growth allows. For a caller that may skip the growth's queries where even
// that ball is of no use.
Sphere grown_extent(const Sphere& sphere, const ClosestPoint& closest, double max_radius, double growth);

// The largest inscribed ball tangent to the surface at `point` (the shrinking ball of Ma et al.
// 2012, on exact closest points): its center on the ray from `point` along `inward`, shrunk from
// `start_radius` until no surface point lies inside it. Points on triangles that have one of
// `own_corners` as a corner do not shrink it: at a vertex of a curved mesh those faces meet at a
// corner that no ball touches, and the ball is kept that the smooth surface would allow. The
// radius is then the exact distance from the center (the ball is inside and touches the point
// up to that corner's sagitta). Returns radius 0 where the ball shrinks below `min_radius` or
// its center is not inside (a sharp edge, a flipped normal).
Sphere tangent_ball(const MeshQuery& mesh, const Eigen::Vector3d& point, const Eigen::Vector3d& inward,
                    const std::vector<Eigen::Vector3d>& own_corners, double start_radius, double min_radius);

// The largest inscribed ball whose center lies on the ray from `point` along `inward` and whose
// surface passes within `slack` of `point`: its radius is the exact distance from the center,
// and the gap at `point` (offset less radius) only grows with the offset (the distance is
// 1-Lipschitz), so the offset is bisected up to `max_offset`. Where tangent_ball's ball is held
// off by a corner of the point's own faces, this ball still reaches it. Radius 0 where none
// larger than `min_radius` does (a knife edge) or its center is not inside.
Sphere touching_ball(const MeshQuery& mesh, const Eigen::Vector3d& point, const Eigen::Vector3d& inward, double slack,
                     double max_offset, double min_radius);

// Balls nested in `ball` that touch the surface where it does, at `point`: centres a half, a
// quarter, ... of the way from `point` to the ball's centre, each radius the exact distance
// there, down to the first whose radius is at most `least`. A skinned sphere keeps one radius
// over a whole clip, and a smaller ball keeps more of its own where parts move against each other.
std::vector<Sphere> nested_balls(const MeshQuery& mesh, const Eigen::Vector3d& point, const Sphere& ball, double least);

// Inscribed balls within `within` of `point`, off the surface: centres at a half, three quarters
// and 0.95 of `within` from it, along `inward` and tilted 30 and 60 degrees from it six ways
// round, each radius the exact distance there (a centre not inside gives none). Each reaches the
// point within `within` whatever its radius. Where the skin folds, a ball touching a point is cut
// in some frame of the clip, and a skinned sphere keeps one radius; a small ball a little deeper
// or to one side can stay inside in every frame and still reach the point.
std::vector<Sphere> balls_around(const MeshQuery& mesh, const Eigen::Vector3d& point, const Eigen::Vector3d& inward,
                                 double within);

// How far spheres grow by default (the offset at most doubles the radius): enough to reach the
// medial axis from a candidate off it by a voxel or two, little enough that a pose's sphere
// stays on the same part of the body as the rest sphere it came from.
constexpr double kDefaultGrowth = 1.0;

}  // namespace spx
