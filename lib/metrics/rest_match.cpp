#include "metrics/rest_match.hpp"

#include <algorithm>

#include "core/error.hpp"
#include "core/format.hpp"
#include "mesh/mesh_query.hpp"

namespace spx {

double check_rest_holds(const ProxyModel& proxy, const TriMesh& rest, const std::string& subject, const std::string& kind) {
  const MeshQuery query(rest);
  size_t outside = 0, spheres = 0;
  double over = 0;
  for (const Sphere& s : proxy.poses.at(0).spheres) {
    if (!(s.radius > 0)) continue;
    ++spheres;
    // A centre outside pokes its sphere out by its radius and the centre's own distance.
    const bool in = query.inside(s.center);
    outside += in ? 0 : 1;
    over = std::max(over, s.radius + (in ? -1 : 1) * query.distance(s.center));
  }
  const double diag = rest.diagonal();
  if (outside > 0 || over > 1e-3 * diag)
    fail_input(subject, "its rest does not hold the proxy's rest spheres (" + std::to_string(outside) + " of " +
                            std::to_string(spheres) + " centres outside, the union up to " + num(100 * over / diag) +
                            " % of its diagonal out): not the " + kind + " the proxy was made from (" +
                            proxy.poses.at(0).source + ")");
  return diag;
}

}  // namespace spx
