#include "posemap/clip_radius.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <tbb/parallel_for.h>

#include "core/format.hpp"
#include "mesh/mesh_query.hpp"

namespace spx {
ClipRadius::ClipRadius(const SkinFile& skin, const TriMesh& rest, double max_radius, double overshoot)
    : overshoot_(overshoot),
      clip_(skin.clip),
      rest_(rest),
      max_radius_(max_radius),
      vertices_(skin, rest.vertices),
      deforming_(rest) {}

TriMesh ClipRadius::mesh_at(size_t k) const { return {vertices_.all(clip_.matrices[k]), rest_.triangles}; }

// A few times skinned at once: their meshes built in parallel, then each sphere walks them in
// order. A block of this many costs a few MB.
constexpr size_t kTimesAtOnce = 16;

struct ClipRadius::Time {
  std::optional<DeformingQuery::Shape> shape;  // a closed mesh
  std::unique_ptr<MeshQuery> query;            // another
};

double ClipRadius::least_at(const Time& time, const Eigen::Vector3d& c, double r) const {
  if (time.query) return time.query->inside(c) ? std::min(r, time.query->distance(c) + overshoot_) : 0.0;
  // Only a surface nearer than r less the overshoot lowers r: the search looks no farther.
  const double bound = r - overshoot_;
  const double d = bound > 0 ? time.shape->signed_distance_within(c, bound) : std::numeric_limits<double>::infinity();
  if (d < 0) return -d + overshoot_;
  // Nothing nearer: the centre is inside or out (a jump between times). Or the closest surface
  // says outside, which where parts of the body pass through each other (legs in a stride) can
  // be a wall inside the solid. The winding number decides.
  if (!time.shape->inside(c)) return 0.0;
  return std::isfinite(d) ? d + overshoot_ : r;
}

std::vector<double> ClipRadius::least(const std::vector<SkinInfluence>& influences, const std::vector<double>& radius,
                                      const Log* log) const {
  std::vector<double> out(radius);
  for (double& r : out) r = r > 0 ? std::min(r, max_radius_) : 0.0;
  // A percentage where the walk takes seconds: a million spheres times times.
  if (out.size() * time_count() < size_t(1000000)) log = nullptr;
  const std::string stage = "holding " + std::to_string(out.size()) + " spheres over the clip's " +
                            std::to_string(time_count()) + " times";
  const size_t blocks = (time_count() + kTimesAtOnce - 1) / kTimesAtOnce;
  for (size_t first = 0; first < time_count(); first += kTimesAtOnce) {
    if (log) log->progress(stage.c_str(), first / kTimesAtOnce, blocks);
    const size_t count = std::min(kTimesAtOnce, time_count() - first);
    std::vector<Time> block(count);
    tbb::parallel_for(size_t(0), count, [&](size_t t) {
      Time& time = block[t];
      if (deforming_.closed())
        time.shape.emplace(deforming_.shape(vertices_.all(clip_.matrices[first + t])));
      else
        time.query = std::make_unique<MeshQuery>(mesh_at(first + t));
    });
    tbb::parallel_for(size_t(0), out.size(), [&](size_t i) {
      for (size_t t = 0; t < count && out[i] > 0; ++t)
        out[i] = least_at(block[t], skin_point(influences[i], clip_.matrices[first + t]), out[i]);
    });
  }
  if (log) log->progress(stage.c_str(), blocks, blocks);
  return out;
}

ClipOvershoot check_over_clip(const SkinFile& skin, const TriMesh& rest, double max_radius, const SphereSet& spheres,
                              const std::vector<SkinInfluence>& influences, Log& log) {
  std::vector<double> radii;
  for (const Sphere& s : spheres) radii.push_back(s.radius);
  const std::vector<double> held = ClipRadius(skin, rest, max_radius).least(influences, radii, &log);
  const double rounding = 1e-6 * rest.diagonal();  // past float rounding of the exact distance
  ClipOvershoot out{skin.clip.times.size()};
  for (size_t i = 0; i < radii.size(); ++i) {
    if (!(radii[i] > 0) || held[i] >= std::min(radii[i], max_radius) - rounding) continue;
    ++out.spheres_out;
    out.centres_outside += held[i] == 0;
    out.worst = std::max(out.worst, radii[i] - held[i]);
  }
  // Counted past rounding; said past a thousandth of the diagonal, or where a centre leaves the body.
  if (out.centres_outside > 0 || out.worst > 1e-3 * rest.diagonal())
    log.warn("between the poses given, " + std::to_string(out.spheres_out) + " of " + std::to_string(radii.size()) +
             " spheres poke out of the body at some of the clip's " + std::to_string(out.times) + " times (by up to " +
             num(out.worst) + ", " + num(100 * out.worst / rest.diagonal()) + " % of the diagonal; " +
             std::to_string(out.centres_outside) + " centres leave it): --hold-over-clip keeps them inside");
  return out;
}

}  // namespace spx
