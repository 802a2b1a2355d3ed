#include "posemap/clip_radius.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <tbb/parallel_for.h>

#include "mesh/mesh_query.hpp"
#include "mesh/winding_number.hpp"

namespace spx {
namespace {

Eigen::Matrix4d blend(const JointWeights& w, const JointMatrices& m) {
  Eigen::Matrix4d sum = Eigen::Matrix4d::Zero();
  for (const auto& [joint, weight] : w) sum += weight * m[size_t(joint)];
  return sum;
}

}  // namespace

ClipRadius::ClipRadius(const SkinFile& skin, const TriMesh& rest, double max_radius)
    : clip_(skin.clip), rest_(rest), max_radius_(max_radius), weights_(skin.vertex_weights), bind_(rest.vertices),
      deforming_(rest) {
  for (size_t v = 0; v < bind_.size(); ++v) {
    if (weights_[v].empty()) continue;  // no joint weighs it: it stays where it is
    const Eigen::Matrix4d at_rest = blend(weights_[v], skin.rest);
    bind_[v] = at_rest.fullPivLu().solve(rest.vertices[v].homogeneous()).head<3>();
  }
}

TriMesh ClipRadius::mesh_at(size_t k) const {
  TriMesh mesh;
  mesh.triangles = rest_.triangles;
  mesh.vertices.resize(bind_.size());
  for (size_t v = 0; v < bind_.size(); ++v)
    mesh.vertices[v] = weights_[v].empty() ? bind_[v] : (blend(weights_[v], clip_.matrices[k]) * bind_[v].homogeneous()).head<3>();
  return mesh;
}

std::vector<double> ClipRadius::radii_at(size_t k, const std::vector<SkinInfluence>& influences,
                                         const std::vector<double>& radius) const {
  std::vector<double> r(influences.size(), 0.0);
  const auto fill = [&](const auto& signed_distance) {
    for (size_t i = 0; i < r.size(); ++i) {
      if (!(radius[i] > 0)) continue;
      const double d = signed_distance(skin_point(influences[i], clip_.matrices[k]));
      r[i] = d < 0 ? std::min(max_radius_, -d) : 0.0;
    }
  };
  if (deforming_.closed()) {
    // Where parts of the body pass through each other (legs in a stride) the closest surface can
    // be a wall inside the solid, and its pseudo-normal says outside: the exact winding number
    // decides those.
    const TriMesh mesh = mesh_at(k);
    const DeformingQuery::Shape shape = deforming_.shape(mesh.vertices);
    fill([&](const Eigen::Vector3d& c) {
      const double d = shape.signed_distance(c);
      return d >= 0 && winding_number_exact(mesh, c) > 0.5 ? -d : d;
    });
  } else {
    const MeshQuery query(mesh_at(k));
    fill([&](const Eigen::Vector3d& c) { return query.inside(c) ? -query.distance(c) : 1.0; });
  }
  return r;
}

std::vector<double> ClipRadius::least(const std::vector<SkinInfluence>& influences, const std::vector<double>& radius) const {
  const size_t n = influences.size(), times = time_count();
  std::vector<std::vector<double>> at(times);  // [time][sphere], reduced in order below
  tbb::parallel_for(size_t(0), times, [&](size_t k) { at[k] = radii_at(k, influences, radius); });
  std::vector<double> out(radius);
  for (size_t k = 0; k < times; ++k)
    for (size_t i = 0; i < n; ++i)
      if (out[i] > 0) out[i] = std::min(out[i], at[k][i]);
  return out;
}

}  // namespace spx
