#include "metrics/rest_match.hpp"

#include <algorithm>

#include "core/error.hpp"
#include "core/format.hpp"
#include "extract/asset.hpp"
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

std::vector<std::string> warn_meshes_without_spheres(const ProxyModel& proxy, const Asset& asset,
                                                     const std::string& effect, Log& log) {
  // One box per name, as --mesh takes a name (a glTF mesh's primitives, a mesh placed twice).
  const std::vector<Eigen::Vector3d> rest = asset.rest(true);
  std::vector<std::string> names;
  std::vector<Eigen::AlignedBox3d> boxes;
  size_t first = 0;
  for (const AssetMesh& m : asset.meshes()) {
    if (!m.used) continue;
    const size_t k = size_t(std::find(names.begin(), names.end(), m.name) - names.begin());
    if (k == names.size()) names.push_back(m.name), boxes.emplace_back();
    for (size_t v = first; v < first + m.vertices && v < rest.size(); ++v) boxes[k].extend(rest[v]);
    first += m.vertices;
  }
  std::vector<std::string> none, every;
  size_t spheres = 0;
  for (const Sphere& s : proxy.poses.at(0).spheres) spheres += s.radius > 0;
  for (size_t k = 0; k < names.size(); ++k) {
    Eigen::AlignedBox3d box = boxes[k];
    // A hair wider than the box: a centre on a flat part's face is in it.
    const double slack = 1e-6 * (box.isEmpty() ? 0.0 : box.diagonal().norm());
    box.min().array() -= slack, box.max().array() += slack;
    size_t held = 0;
    for (const Sphere& s : proxy.poses.at(0).spheres) held += s.radius > 0 && box.contains(s.center);
    if (held == 0) none.push_back(names[k]);
    if (held == spheres) every.push_back(names[k]);
  }
  if (names.size() < 2 || none.empty() || spheres == 0) return {};
  log.warn(std::to_string(none.size()) + " of the " + std::to_string(names.size()) + " meshes of " + asset.path() +
           " hold no sphere of the proxy (" + one_line(quoted_names(none), 200) + "): " + effect +
           (every.empty() ? "" : "; a proxy of one mesh (pose-extract --mesh) takes --mesh " + every.front()) +
           (every.size() > 1 ? " (or " + one_line(quoted_names({every.begin() + 1, every.end()}), 200) + ")" : ""));
  return none;
}

}  // namespace spx
