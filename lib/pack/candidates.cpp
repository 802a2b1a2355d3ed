#include "pack/candidates.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>

#include "core/random.hpp"
#include "core/tolerance.hpp"
#include "mesh/normals.hpp"
#include "pack/sample_grid.hpp"

namespace spx {
CandidateOptions candidate_options(const PackOptions& pack) {
  CandidateOptions c;
  c.min_radius = pack.min_radius;
  c.max_radius = pack.max_radius;
  c.field_bounds_radius = pack.field_bounds_radius;
  return c;
}

std::vector<MedialVoxel> medial_voxels(const DenseField& field) {
  const GridShape& g = field.shape;
  const double h = g.voxel_size;
  // Near-medial: off the medial axis, the distance grows by about h/sqrt(3) or more towards
  // some face neighbour; on it (and across a part a few voxels thin) no neighbour is deeper.
  std::vector<char> medial(g.count(), 0);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, g.count(), 4096), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t idx = r.begin(); idx != r.end(); ++idx) {
      const float v = field.values[idx];
      if (!(v < 0)) continue;
      bool deeper = false;
      g.for_each_face_neighbour(idx, g.coords(idx), [&](size_t m) { deeper = deeper || field.values[m] <= v - 0.5f * float(h); });
      medial[idx] = !deeper;
    }
  });
  std::vector<MedialVoxel> out;
  for (size_t idx = 0; idx < g.count(); ++idx)
    if (medial[idx]) out.push_back({g.world(idx), -double(field.values[idx])});
  return out;
}

namespace {
// A candidate in two steps: its seed (the voxel's own sphere and, where it grows, its closest
// point: one query), then the growth (grow_inscribed: a few queries more), which
// CandidatesOnDemand skips where even the ball it could grow into is of no use (seed_extent).
struct CandidateSeed {
  Sphere sphere;
  ClosestPoint closest;
  bool grows = false;
};

CandidateSeed candidate_seed(const MedialVoxel& voxel, const MeshQuery& mesh, const CandidateOptions& opt, double h) {
  const Eigen::Vector3d& c = voxel.center;
  // A closed mesh's winding number is constant off its surface: more than a voxel deep by the
  // field (within a fraction of one of the truth) is inside without asking it. (An open mesh's
  // varies across its holes, where the field's depth says nothing.)
  const bool surely_inside = !opt.field_bounds_radius && voxel.depth > h;
  if (!surely_inside && !mesh.inside(c)) return {{c, 0.0}, {}, false};
  if (opt.field_bounds_radius)
    return {{c, std::max(0.0, std::min({opt.max_radius, mesh.distance(c), voxel.depth - kFieldMargin * h}))}, {}, false};
  // Grown from the closest point that gives its radius: one query for both.
  const ClosestPoint closest = mesh.closest(c);
  return {{c, std::max(0.0, std::min(opt.max_radius, closest.tree_distance))}, closest, true};
}

Sphere seed_extent(const CandidateSeed& seed, const CandidateOptions& opt) {
  return seed.grows ? grown_extent(seed.sphere, seed.closest, opt.max_radius, opt.growth) : seed.sphere;
}

Sphere grow_seed(const CandidateSeed& seed, const MeshQuery& mesh, const CandidateOptions& opt) {
  return seed.grows ? grow_inscribed(mesh, seed.sphere, seed.closest, opt.max_radius, opt.growth) : seed.sphere;
}
}  // namespace

Sphere inscribed_candidate(const MedialVoxel& voxel, const MeshQuery& mesh, const CandidateOptions& opt, double h) {
  return grow_seed(candidate_seed(voxel, mesh, opt, h), mesh, opt);
}

SphereSet inscribed_candidates(const DenseField& field, const MeshQuery& mesh, const CandidateOptions& opt) {
  const std::vector<MedialVoxel> voxels = medial_voxels(field);
  SphereSet out(voxels.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, voxels.size(), 64), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t n = r.begin(); n != r.end(); ++n) out[n] = inscribed_candidate(voxels[n], mesh, opt, field.shape.voxel_size);
  });
  out.erase(std::remove_if(out.begin(), out.end(),
                           [&](const Sphere& s) { return !(s.radius > 0) || s.radius < opt.min_radius; }),
            out.end());
  return out;
}

CandidatesOnDemand::CandidatesOnDemand(const DenseField& field, const CandidateOptions& options)
    : voxels_(medial_voxels(field)),
      options_(options),
      h_(field.shape.voxel_size),
      sphere_(voxels_.size()),
      state_(voxels_.size(), unknown) {}

SphereSet CandidatesOnDemand::offer_near(const std::vector<Eigen::Vector3d>& points, double reach,
                                         const MeshQuery& mesh) {
  if (points.empty()) return {};
  // Only the points in the grid cells a ball reaches are tested (by the same rule as all of them).
  const detail::SampleGrid grid(points);
  auto near = [&](const Eigen::Vector3d& c, double radius) {
    return grid.any_near(c, radius + reach, [&](uint32_t i) { return (points[i] - c).norm() - radius <= reach; });
  };
  std::vector<char> take(voxels_.size(), 0);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, voxels_.size(), 64), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t v = r.begin(); v != r.end(); ++v) {
      if (state_[v] == offered) continue;
      if (state_[v] == unknown) {
        if (!near(voxels_[v].center, candidate_extent(voxels_[v], options_, h_))) continue;
        // The growth's queries are most of a candidate's cost: skipped (and the voxel left for
        // a later offer) where even the largest ball it could grow into reaches no point.
        const CandidateSeed seed = candidate_seed(voxels_[v], mesh, options_, h_);
        const Sphere extent = seed_extent(seed, options_);
        if (!near(extent.center, extent.radius)) continue;
        sphere_[v] = grow_seed(seed, mesh, options_);
        state_[v] = known;
      }
      const Sphere& s = sphere_[v];
      take[v] = s.radius > 0 && s.radius >= options_.min_radius && near(s.center, s.radius);
    }
  });
  SphereSet out;
  for (size_t v = 0; v < voxels_.size(); ++v)
    if (take[v]) {
      out.push_back(sphere_[v]);
      state_[v] = offered;
    }
  return out;
}

CandidatesOnDemand::CandidatesOnDemand(std::vector<MedialVoxel> voxels, double h, const CandidateOptions& options)
    : voxels_(std::move(voxels)), options_(options), h_(h), sphere_(voxels_.size()), state_(voxels_.size(), unknown) {}

size_t CandidatesOnDemand::found() const {
  return size_t(std::count_if(state_.begin(), state_.end(), [](char s) { return s != unknown; }));
}

std::vector<std::pair<uint32_t, Sphere>> CandidatesOnDemand::grown() const {
  std::vector<std::pair<uint32_t, Sphere>> out;
  for (size_t v = 0; v < voxels_.size(); ++v)
    if (state_[v] != unknown) out.emplace_back(uint32_t(v), sphere_[v]);
  return out;
}

void CandidatesOnDemand::give_grown(const std::vector<std::pair<uint32_t, Sphere>>& grown) {
  for (const auto& [v, s] : grown)
    if (v < voxels_.size() && state_[v] == unknown) sphere_[v] = s, state_[v] = known;
}

std::vector<Eigen::Vector3d> surface_samples(const TriMesh& mesh, size_t area_samples, uint64_t seed) {
  return sample_surface(mesh, area_samples, seed).points;
}

SurfaceSamples sample_surface(const TriMesh& mesh, size_t area_samples, uint64_t seed) {
  SurfaceSamples out;
  out.points = mesh.vertices;
  std::vector<double> cumulative(mesh.triangles.size());
  double total = 0;
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const Eigen::Vector3i& f = mesh.triangles[t];
    total += 0.5 * (mesh.vertices[size_t(f[1])] - mesh.vertices[size_t(f[0])])
                       .cross(mesh.vertices[size_t(f[2])] - mesh.vertices[size_t(f[0])])
                       .norm();
    cumulative[t] = total;
  }
  if (!(total > 0)) return out;
  SplitMix rng{seed};
  for (size_t n = 0; n < area_samples; ++n) {
    const double pick = rng.uniform() * total;
    const size_t t = std::min(size_t(std::upper_bound(cumulative.begin(), cumulative.end(), pick) - cumulative.begin()),
                              cumulative.size() - 1);
    const double a = std::sqrt(rng.uniform()), b = rng.uniform();
    const Eigen::Vector3i& f = mesh.triangles[t];
    out.points.push_back((1 - a) * mesh.vertices[size_t(f[0])] + a * (1 - b) * mesh.vertices[size_t(f[1])] +
                         a * b * mesh.vertices[size_t(f[2])]);
    out.triangle.push_back(int(t));
  }
  return out;
}

std::vector<uint32_t> spaced_points(const std::vector<Eigen::Vector3d>& points, size_t count, double spacing) {
  const std::vector<Eigen::Vector3d> first(points.begin(), points.begin() + long(count));
  const detail::SampleGrid grid(first);
  std::vector<char> near_kept(count, 0);
  std::vector<uint32_t> kept;
  for (size_t i = 0; i < count; ++i) {
    if (near_kept[i]) continue;
    kept.push_back(uint32_t(i));
    grid.near(first[i], spacing, [&](uint32_t j) { near_kept[j] |= (first[j] - first[i]).norm() <= spacing; });
  }
  return kept;
}

std::vector<uint32_t> samples_to_cover(const std::vector<Eigen::Vector3d>& points, size_t vertices, double spacing,
                                       double& spaced_by) {
  spaced_by = 0;
  if (spacing > 0) {
    std::vector<uint32_t> kept = spaced_points(points, vertices, spacing);
    // Where most are kept, the whole problem costs little more.
    if (kept.size() < vertices / 2) {
      spaced_by = spacing;
      for (size_t i = vertices; i < points.size(); ++i) kept.push_back(uint32_t(i));
      return kept;
    }
  }
  std::vector<uint32_t> every(points.size());
  std::iota(every.begin(), every.end(), 0u);
  return every;
}

double deepest_radius(const DenseField& field) {
  float deepest = 0;
  for (float v : field.values) deepest = std::min(deepest, v);
  return -double(deepest) + 2 * field.shape.voxel_size;
}

TangentCandidates tangent_candidates(const MeshQuery& mesh, const TriMesh& surface, const SurfaceSamples& samples,
                                     const DenseField& field, double start_radius, const CandidateOptions& opt) {
  std::vector<uint32_t> every(samples.points.size());
  std::iota(every.begin(), every.end(), 0u);
  return tangent_candidates(mesh, surface, samples, every, &field, start_radius, opt);
}

TangentCandidates tangent_candidates(const MeshQuery& mesh, const TriMesh& surface, const SurfaceSamples& samples,
                                     const std::vector<uint32_t>& which, const DenseField* field, double start_radius,
                                     const CandidateOptions& opt) {
  return tangent_candidates_of(tangent_balls(mesh, surface, samples, which, field, start_radius, opt), which, samples,
                               surface);
}

namespace {
// Whether ball s reaches point p within the slack.
bool reaches(const Sphere& s, const Eigen::Vector3d& p, double slack) {
  return s.radius > 0 && (p - s.center).norm() - s.radius <= slack;
}
}  // namespace

TangentCandidates tangent_candidates_of(const std::vector<SampleBalls>& balls, const std::vector<uint32_t>& which,
                                        const SurfaceSamples& samples, const TriMesh& surface) {
  const double slack = kTouchSlack * surface.diagonal();
  TangentCandidates out;
  for (size_t n = 0; n < balls.size(); ++n) {
    for (const Sphere& s : balls[n])
      if (s.radius > 0) out.spheres.push_back(s), out.touches.push_back(which[n]);
    out.touching += balls[n][1].radius > 0;
    out.unreached += !(balls[n][1].radius > 0) && !reaches(balls[n][0], samples.points[which[n]], slack);
  }
  return out;
}

std::vector<SampleBalls> tangent_balls(const MeshQuery& mesh, const TriMesh& surface, const SurfaceSamples& samples,
                                       const std::vector<uint32_t>& which, const DenseField* field, double start_radius,
                                       const CandidateOptions& opt) {
  const std::vector<Eigen::Vector3d> faces = face_normals(surface), normals = angle_weighted_normals(surface, faces);
  const size_t vertices = surface.vertices.size();
  const double diag = surface.diagonal();
  const double least = std::max(opt.min_radius, kTouchSlack * diag), slack = kTouchSlack * diag;
  start_radius = std::min(start_radius, opt.max_radius);
  // Per sample: the tangent ball, and where it misses the sample by more than the slack (a
  // corner of its own faces) also the ball that touches it.
  std::vector<SampleBalls> balls(which.size(), {Sphere{{0, 0, 0}, 0}, Sphere{{0, 0, 0}, 0}});
  auto bounded = [&](Sphere s) {
    if (opt.field_bounds_radius && s.radius > 0)
      s.radius = std::max(0.0, std::min(s.radius, depth_bound(*field, s.center) - kFieldMargin * field->shape.voxel_size));
    s.radius = std::min(s.radius, opt.max_radius);
    if (s.radius < opt.min_radius) s.radius = 0;
    return s;
  };
  tbb::parallel_for(tbb::blocked_range<size_t>(0, balls.size(), 32), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t n = r.begin(); n != r.end(); ++n) {
      const size_t i = which[n];
      const Eigen::Vector3d& p = samples.points[i];
      Eigen::Vector3d inward;
      std::vector<Eigen::Vector3d> own;
      if (i < vertices) {
        inward = -normals[i].normalized();
        own = {p};
      } else {
        const size_t t = size_t(samples.triangle[i - vertices]);
        const Eigen::Vector3i& f = surface.triangles[t];
        own = {surface.vertices[size_t(f[0])], surface.vertices[size_t(f[1])], surface.vertices[size_t(f[2])]};
        inward = -faces[t];
      }
      if (!(inward.norm() > 0.5)) continue;  // no normal: a degenerate corner
      const Sphere tangent = tangent_ball(mesh, p, inward, own, start_radius, least);
      balls[n][0] = bounded(tangent);
      // A sharp corner's ball is small: within the slack of the corner it can be no larger.
      if (!reaches(tangent, p, slack))
        balls[n][1] = bounded(touching_ball(mesh, p, inward, slack, tangent.radius > 0 ? (tangent.center - p).norm() : start_radius,
                                            1e-3 * slack));
    }
  });
  return balls;
}

namespace {
// tangent_candidates' balls through the samples `which`, each given to `add(point, ball, first)`
// (`first`: the sample's first ball, its tangent one where that is not 0).
template <class Add>
void for_each_ball_through(const MeshQuery& mesh, const SurfaceSamples& samples, const std::vector<uint32_t>& which,
                           const DenseField* field, double start_radius, const CandidateOptions& options,
                           const Add& add) {
  const TangentCandidates t = tangent_candidates(mesh, mesh.surface(), samples, which, field, start_radius, options);
  for (size_t n = 0; n < t.spheres.size(); ++n)
    add(samples.points[t.touches[n]], t.spheres[n], n == 0 || t.touches[n - 1] != t.touches[n]);
}
}  // namespace

SphereSet balls_through(const MeshQuery& mesh, const SurfaceSamples& samples, const std::vector<uint32_t>& which,
                        const DenseField* field, double start_radius, const CandidateOptions& options,
                        double nested_down_to) {
  SphereSet out;
  for_each_ball_through(mesh, samples, which, field, start_radius, options,
                        [&](const Eigen::Vector3d& p, const Sphere& ball, bool) {
                          out.push_back(ball);
                          if (nested_down_to > 0)
                            for (const Sphere& s : nested_balls(mesh, p, ball, nested_down_to)) out.push_back(s);
                        });
  return out;
}

SphereSet balls_around_samples(const MeshQuery& mesh, const SurfaceSamples& samples, const std::vector<uint32_t>& which,
                               const DenseField* field, double start_radius, const CandidateOptions& options,
                               double within) {
  SphereSet out;
  for_each_ball_through(mesh, samples, which, field, start_radius, options,
                        [&](const Eigen::Vector3d& p, const Sphere& ball, bool first) {
                          if (!first) return;
                          for (const Sphere& s : balls_around(mesh, p, ball.center - p, within)) out.push_back(s);
                        });
  return out;
}

std::vector<size_t> distinct_centres(const SphereSet& kept, const SphereSet& more, double spacing) {
  std::vector<Eigen::Vector3d> old, fresh;
  for (const Sphere& s : kept) old.push_back(s.center);
  for (const Sphere& s : more) fresh.push_back(s.center);
  std::vector<char> near_old(more.size(), 0);
  if (!old.empty()) {
    const detail::SampleGrid grid(old);
    tbb::parallel_for(size_t(0), more.size(), [&](size_t i) {
      grid.near(fresh[i], spacing, [&](uint32_t j) { near_old[i] |= (old[j] - fresh[i]).norm() < spacing; });
    });
  }
  std::vector<size_t> out;
  if (fresh.empty()) return out;
  const detail::SampleGrid grid(fresh);
  std::vector<char> taken(more.size(), 0);
  for (size_t i = 0; i < more.size(); ++i) {
    if (near_old[i]) continue;
    bool near = false;
    grid.near(fresh[i], spacing, [&](uint32_t j) { near |= taken[j] && (fresh[j] - fresh[i]).norm() < spacing; });
    if (near) continue;
    taken[i] = 1;
    out.push_back(i);
  }
  return out;
}

}  // namespace spx
