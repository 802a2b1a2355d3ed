#include "posemap/clip_radius.hpp"

#include <algorithm>
#include <tbb/parallel_for.h>

#include "mesh/mesh_query.hpp"
#include "mesh/winding_number.hpp"

namespace spx {
ClipRadius::ClipRadius(const SkinFile& skin, const TriMesh& rest, double max_radius)
    : clip_(skin.clip), rest_(rest), max_radius_(max_radius), vertices_(skin, rest.vertices), deforming_(rest) {}

TriMesh ClipRadius::mesh_at(size_t k) const { return {vertices_.all(clip_.matrices[k]), rest_.triangles}; }

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
