#include "mesh/inscribed.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace spx {
namespace {
// The growth's rule, shared by grow_inscribed and grown_extent. A sphere may grow at all (told
// before its closest point is asked):
bool can_grow(const Sphere& sphere, double max_radius, double growth) {
  return sphere.radius > 0 && growth > 0 && !(sphere.radius >= max_radius);
}
// and grows from its closest point p only when tangent there, its radius the distance itself
// (not a cap or a hole's bound):
bool grows_from(const Sphere& sphere, const ClosestPoint& p, double max_radius, double growth) {
  return can_grow(sphere, max_radius, growth) && p.distance > 0 && !(sphere.radius < p.distance * (1 - 1e-9));
}
// to offsets from p along its normal of at most this.
double longest_offset(const ClosestPoint& p, double max_radius, double growth) {
  return std::min(max_radius, p.distance * (1 + growth));
}
}  // namespace

Sphere grow_inscribed(const MeshQuery& mesh, const Sphere& sphere, double max_radius, double growth,
                      const std::function<double(const Eigen::Vector3d&)>& bound) {
  if (!can_grow(sphere, max_radius, growth)) return sphere;
  return grow_inscribed(mesh, sphere, mesh.closest(sphere.center), max_radius, growth, bound);
}

Sphere grow_inscribed(const MeshQuery& mesh, const Sphere& sphere, const ClosestPoint& p, double max_radius,
                      double growth, const std::function<double(const Eigen::Vector3d&)>& bound) {
  if (!grows_from(sphere, p, max_radius, growth)) return sphere;
  const Eigen::Vector3d normal = (sphere.center - p.point) / p.distance;
  auto radius_at = [&](const Eigen::Vector3d& q) {
    const double r = std::min(max_radius, mesh.distance(q, p.point));  // p: closest up to the end
    return bound ? std::min(r, bound(q)) : r;
  };
  // The offsets t whose ball of radius t at p + t n still fits form an interval from 0. Bisect
  // for its end, to 1/64 of the first radius; a miss at t with radius r < t also bounds the end
  // by (t + r) / 2, the distance being 1-Lipschitz.
  double lo = p.distance, hi = longest_offset(p, max_radius, growth), radius = sphere.radius;
  for (int step = 0; step < 7 && hi - lo > p.distance / 64; ++step) {
    const double t = step == 0 ? hi : 0.5 * (lo + hi);
    const double r = radius_at(p.point + t * normal);
    if (r >= t * (1 - 1e-7)) {
      lo = t;
      radius = r;
    } else {
      hi = std::min(t, 0.5 * (t + r));
    }
  }
  if (!(radius > sphere.radius)) return sphere;
  // A closed mesh's winding number is constant off its surface: the grown ball holds the old
  // center and no surface point, so it is inside. An open mesh's varies across its holes:
  // the new center is checked by the tools' rule.
  const Eigen::Vector3d center = p.point + lo * normal;
  if (bound && !mesh.inside(center)) return sphere;
  return {center, radius};
}

Sphere grown_extent(const Sphere& sphere, const ClosestPoint& p, double max_radius, double growth) {
  if (!grows_from(sphere, p, max_radius, growth)) return sphere;  // grow_inscribed returns it as it is
  const double reach = longest_offset(p, max_radius, growth);
  const Eigen::Vector3d normal = (sphere.center - p.point) / p.distance;
  // The margin is far above the rounding of the normal, the offsets and the distances.
  return {p.point + reach * normal, std::max(reach, sphere.radius) * (1 + 1e-6) + (sphere.center - p.point).norm() * 1e-6};
}

Sphere tangent_ball(const MeshQuery& mesh, const Eigen::Vector3d& point, const Eigen::Vector3d& inward,
                    const std::vector<Eigen::Vector3d>& own_corners, double start_radius, double min_radius) {
  double r = start_radius;
  ClosestPoint q;  // the last step's: the next ball passes through it, so it bounds the search
  for (int step = 0; step < 64 && r >= min_radius; ++step) {
    const Eigen::Vector3d c = point + r * inward;
    q = mesh.closest(c, q);
    const double reach = r * (1 - 1e-9);
    if (q.distance >= reach) break;
    // Blocked by the point's own faces: what counts is the nearest point past them.
    const Eigen::Vector3i& f = mesh.mesh().triangles[size_t(q.triangle)];
    const auto& v = mesh.mesh().vertices;
    if (has_corner(own_corners, v[size_t(f[0])], v[size_t(f[1])], v[size_t(f[2])])) {
      q = mesh.closest_apart(c, reach, own_corners);
      if (q.triangle < 0) break;
    }
    // The ball tangent at `point` through q: |point + r' n - q| = r'. q lies inside the current
    // ball, so it is ahead of the tangent plane and r' < r.
    const Eigen::Vector3d d = q.point - point;
    const double ahead = inward.dot(d);
    const double next = ahead > 0 ? 0.5 * d.squaredNorm() / ahead : 0;
    r = next < r ? next : 0.5 * (r + q.distance);  // rounding: still shrink
  }
  if (!(r >= min_radius)) return {point, 0};
  const Eigen::Vector3d c = point + r * inward;
  if (!mesh.inside(c)) return {point, 0};
  return {c, mesh.distance(c)};
}

Sphere touching_ball(const MeshQuery& mesh, const Eigen::Vector3d& point, const Eigen::Vector3d& inward, double slack,
                     double max_offset, double min_radius) {
  auto gap = [&](double t) { return t - mesh.distance(point + t * inward); };
  double lo = 0, hi = max_offset;
  if (gap(hi) > slack) {
    // Bisect in log scale first (the offset spans orders of magnitude), then linearly.
    double t = hi;
    while (t > min_radius && gap(t) > slack) {
      hi = t;
      t *= 0.125;
    }
    if (!(t > min_radius)) return {point, 0};
    lo = t;
    for (int step = 0; step < 24 && hi - lo > 1e-3 * lo; ++step) {
      const double mid = 0.5 * (lo + hi);
      (gap(mid) <= slack ? lo : hi) = mid;
    }
  } else {
    lo = hi;
  }
  const Eigen::Vector3d c = point + lo * inward;
  const double radius = mesh.distance(c);
  if (!(radius >= min_radius) || !mesh.inside(c)) return {point, 0};
  return {c, radius};
}

std::vector<Sphere> nested_balls(const MeshQuery& mesh, const Eigen::Vector3d& point, const Sphere& ball, double least) {
  std::vector<Sphere> out;
  const Eigen::Vector3d offset = ball.center - point;
  for (double share = 0.5; ball.radius > 0 && share > 1e-9; share *= 0.5) {
    const Eigen::Vector3d c = point + share * offset;
    const double r = mesh.distance(c);
    if (!(r > 0) || !mesh.inside(c)) break;
    out.push_back({c, r});
    if (r <= least) break;
  }
  return out;
}

std::vector<Sphere> balls_around(const MeshQuery& mesh, const Eigen::Vector3d& point, const Eigen::Vector3d& inward,
                                 double within) {
  std::vector<Sphere> out;
  if (!(within > 0) || !(inward.norm() > 0)) return out;
  const Eigen::Vector3d n = inward.normalized(), u = n.unitOrthogonal(), v = n.cross(u);
  for (double share : {0.5, 0.75, 0.95})
    for (int tilt = 0; tilt < 3; ++tilt)
      for (int turn = 0; turn < (tilt == 0 ? 1 : 6); ++turn) {
        const double a = tilt * M_PI / 6, b = turn * M_PI / 3;
        const Eigen::Vector3d c =
            point + share * within * (std::cos(a) * n + std::sin(a) * (std::cos(b) * u + std::sin(b) * v));
        const double r = mesh.distance(c);
        if (r > 0 && mesh.inside(c)) out.push_back({c, r});
      }
  return out;
}

}  // namespace spx
