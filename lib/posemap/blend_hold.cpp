#include "posemap/blend_hold.hpp"

#include <algorithm>
#include <tbb/parallel_for.h>

#include "core/error.hpp"
#include "mesh/mesh_query.hpp"

namespace spx {

std::vector<std::vector<double>> blends_to_hold(size_t poses, bool morph_targets) {
  std::vector<std::vector<double>> out;
  for (size_t a = 0; a < poses; ++a)
    for (size_t b = a + 1; b < poses; ++b) {
      std::vector<double> w(poses, 0.0);
      w[a] = w[b] = 0.5;
      out.push_back(w);
    }
  const size_t targets = poses > 0 ? poses - 1 : 0;
  if (!morph_targets || targets < 2) return out;
  auto add_set = [&](const std::vector<size_t>& set) {
    std::vector<double> w(poses, 0.0);
    w[0] = 1.0 - double(set.size());
    for (size_t t : set) w[t + 1] = 1.0;
    out.push_back(w);
  };
  if (targets > 8) {
    for (size_t a = 0; a < targets; ++a)
      for (size_t b = a + 1; b < targets; ++b) add_set({a, b});
    return out;
  }
  for (uint32_t mask = 1; mask < (1u << targets); ++mask) {
    if (__builtin_popcount(mask) < 2) continue;
    std::vector<size_t> set;
    for (size_t t = 0; t < targets; ++t)
      if (mask & (1u << t)) set.push_back(t);
    add_set(set);
  }
  return out;
}

namespace {

// At one blend, per sphere: how far it pokes out (its summed radius less its summed centre's
// depth; radii summed below 0 count as 0, as the runtime clamps them), and its depth.
struct AtBlend {
  std::vector<double> over, depth, radius;
};

AtBlend measure_blend(const ProxyModel& proxy, const std::vector<const TriMesh*>& meshes, const std::vector<double>& w) {
  TriMesh mesh;
  mesh.triangles = meshes[0]->triangles;
  mesh.vertices.assign(meshes[0]->vertices.size(), Eigen::Vector3d::Zero());
  for (size_t i = 0; i < meshes.size(); ++i)
    if (w[i] != 0)
      for (size_t v = 0; v < mesh.vertices.size(); ++v) mesh.vertices[v] += w[i] * meshes[i]->vertices[v];
  const MeshQuery query(mesh);
  const size_t n = proxy.sphere_count();
  AtBlend out{std::vector<double>(n), std::vector<double>(n), std::vector<double>(n)};
  for (size_t j = 0; j < n; ++j) {
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    double r = 0;
    for (size_t i = 0; i < proxy.poses.size(); ++i) {
      c += w[i] * proxy.poses[i].spheres[j].center;
      r += w[i] * proxy.poses[i].spheres[j].radius;
    }
    out.radius[j] = std::max(r, 0.0);
    out.depth[j] = -query.signed_distance(c);
    out.over[j] = out.radius[j] > 0 ? out.radius[j] - out.depth[j] : 0.0;
  }
  return out;
}

}  // namespace

BlendHold hold_over_blends(ProxyModel& proxy, const std::vector<const TriMesh*>& meshes,
                           const std::vector<std::vector<double>>& blends) {
  if (meshes.size() != proxy.poses.size()) fail_usage("hold_over_blends", "one mesh per pose");
  std::vector<AtBlend> at(blends.size());
  tbb::parallel_for(size_t(0), blends.size(), [&](size_t b) { at[b] = measure_blend(proxy, meshes, blends[b]); });
  BlendHold out;
  out.blends = blends.size();
  const size_t n = proxy.sphere_count();
  std::vector<double> scale(n, 1.0);
  for (size_t b = 0; b < blends.size(); ++b)
    for (size_t j = 0; j < n; ++j) {
      if (at[b].over[j] > out.overshoot) out.overshoot = at[b].over[j], out.worst = blends[b];
      if (at[b].over[j] <= 0) continue;
      scale[j] = at[b].depth[j] > 0 ? std::min(scale[j], at[b].depth[j] / at[b].radius[j]) : 0.0;
    }
  for (size_t j = 0; j < n; ++j) {
    if (scale[j] >= 1) continue;
    ++(scale[j] > 0 ? out.shrunk : out.emptied);
    if (scale[j] > 0) out.least_scale = std::min(out.least_scale, scale[j]);
    for (ProxyPose& p : proxy.poses) p.spheres[j].radius *= scale[j];
  }
  return out;
}

}  // namespace spx
