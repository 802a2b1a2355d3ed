#include "mesh/inscribed.hpp"

#include <algorithm>
#include <limits>

namespace spx {

Sphere grow_inscribed(const MeshQuery& mesh, const Sphere& sphere, double max_radius, double growth,
                      const std::function<double(const Eigen::Vector3d&)>& bound) {
  if (!(sphere.radius > 0) || !(growth > 0) || sphere.radius >= max_radius) return sphere;
  const ClosestPoint p = mesh.closest(sphere.center);
  // Tangent at p only when the radius is the distance itself (not a cap or a hole's bound).
  if (!(p.distance > 0) || sphere.radius < p.distance * (1 - 1e-9)) return sphere;
  const Eigen::Vector3d normal = (sphere.center - p.point) / p.distance;
  auto radius_at = [&](const Eigen::Vector3d& q) {
    const double r = std::min(max_radius, mesh.distance(q, p.point));  // p: closest up to the end
    return bound ? std::min(r, bound(q)) : r;
  };
  // The offsets t whose ball of radius t at p + t n still fits form an interval from 0. Bisect
  // for its end, to 1/64 of the first radius; a miss at t with radius r < t also bounds the end
  // by (t + r) / 2, the distance being 1-Lipschitz.
  double lo = p.distance, hi = std::min(max_radius, p.distance * (1 + growth)), radius = sphere.radius;
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

}  // namespace spx
