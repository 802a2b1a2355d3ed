#pragma once
// What sphere-pack's cover chooses from and what it covers: inscribed candidate spheres (centre
// at a near-medial interior voxel, radius the exact distance to the surface, grown to the
// largest inscribed sphere containing it) and surface samples (every vertex plus area samples).
#include <array>
#include <cstdint>
#include <vector>

#include "core/sphere.hpp"
#include "io/dense_field.hpp"
#include "mesh/inscribed.hpp"
#include "mesh/mesh_query.hpp"
#include "pack/pack.hpp"

namespace spx {

struct CandidateOptions {
  double min_radius = 0;
  double max_radius = 1e300;
  bool field_bounds_radius = false;  // open meshes: the field bounds radii across the holes too
  // Each candidate grown to the largest inscribed sphere containing it (grow_inscribed), so
  // centers off the medial axis by a voxel reach it; closed meshes only (the field's bound
  // across an open mesh's holes holds at voxel centers alone).
  double growth = kDefaultGrowth;
};

// The candidates' limits from a packing's (its radius limits and whether the field bounds radii),
// so that both methods keep the same spheres out.
CandidateOptions candidate_options(const PackOptions& pack);

// Inscribed candidate spheres from the interior voxels of `field` that lie near its medial
// axis (no face neighbour deeper by half a voxel or more), radii from `mesh`, each grown to the
// largest inscribed sphere containing it (options.growth). Every such voxel is a candidate, so
// a finer field offers finer ones; a cover at delta thins them by what they cover
// (CoverProblem::merge). Made of the two steps below, in voxel order; candidates of radius 0
// or below the least radius are dropped.
SphereSet inscribed_candidates(const DenseField& field, const MeshQuery& mesh, const CandidateOptions& options);

// A near-medial interior voxel: its centre and the field's depth there.
struct MedialVoxel {
  Eigen::Vector3d center;
  double depth = 0;
};
std::vector<MedialVoxel> medial_voxels(const DenseField& field);

// The candidate at one near-medial voxel of a field of voxel size h (radius 0 where it has none).
Sphere inscribed_candidate(const MedialVoxel& voxel, const MeshQuery& mesh, const CandidateOptions& options, double h);

// A radius about the voxel's centre that holds its candidate, grown or not, for a search that
// skips voxels before paying for their candidates: the radius is the exact distance, which the
// field's (to some triangle of the same surface) is never below, and growth moves the centre
// by at most `growth` radii, its radius keeping up.
inline double candidate_extent(const MedialVoxel& voxel, const CandidateOptions& options, double h) {
  const double r = std::min(options.max_radius, voxel.depth + 0.1 * h);
  return options.field_bounds_radius ? r : r * (1 + 2 * options.growth);
}

// A field's inscribed candidates offered a few at a time: those within `reach` of some given
// point (a sample no other candidate reaches), each once, in voxel order, as inscribed_candidates
// gives them. A voxel's candidate is found only when a point is within reach of its extent, so
// that the many frames of a clip cost what their points ask, not their whole fields. The field
// is not kept.
class CandidatesOnDemand {
 public:
  CandidatesOnDemand(const DenseField& field, const CandidateOptions& options);
  // From the near-medial voxels of a field of voxel size h listed before (a cache's).
  CandidatesOnDemand(std::vector<MedialVoxel> voxels, double h, const CandidateOptions& options);
  // Those not offered before within `reach` of one of `points`, found on `mesh` (the field's).
  SphereSet offer_near(const std::vector<Eigen::Vector3d>& points, double reach, const MeshQuery& mesh);
  size_t found() const;  // candidates found so far (what the offers cost)

  // What a cache keeps: the voxels, and the candidates grown so far by voxel; grown ones given
  // back (those of the same voxels, field, mesh and options) are offered as if grown here.
  const std::vector<MedialVoxel>& voxels() const { return voxels_; }
  double voxel_size() const { return h_; }
  std::vector<std::pair<uint32_t, Sphere>> grown() const;
  void give_grown(const std::vector<std::pair<uint32_t, Sphere>>& grown);

 private:
  enum State : char { unknown, known, offered };
  std::vector<MedialVoxel> voxels_;
  CandidateOptions options_;
  double h_ = 0;
  SphereSet sphere_;
  std::vector<char> state_;
};

// Of `more`, those whose centre is at least `spacing` from every centre of `kept` and of those of
// `more` taken before it (in order): candidates offered again and again from alike poses of a
// clip, mapped back to the rest, land on one another. Returns indices into `more`, ascending.
std::vector<size_t> distinct_centres(const SphereSet& kept, const SphereSet& more, double spacing);

// Points on a surface and where each came from.
struct SurfaceSamples {
  std::vector<Eigen::Vector3d> points;  // every vertex, then the area samples
  std::vector<int> triangle;            // the triangle of each area sample (after the vertices)
};

// Every vertex of `mesh`, then `area_samples` points drawn uniformly by area (seeded).
SurfaceSamples sample_surface(const TriMesh& mesh, size_t area_samples, uint64_t seed);
std::vector<Eigen::Vector3d> surface_samples(const TriMesh& mesh, size_t area_samples, uint64_t seed);

// The first `count` of `points` thinned to `spacing`: in order, each point kept unless one kept
// before lies within `spacing` of it. Every point of the first `count` is then within `spacing`
// of a kept one, and no two kept ones are closer than that. Indices, ascending.
std::vector<uint32_t> spaced_points(const std::vector<Eigen::Vector3d>& points, size_t count, double spacing);

// A mesh whose vertices lie much closer together than the tolerance (a scan, a subdivided
// sculpt): a cover is first solved on vertices this part of the tolerance apart, then every
// vertex is checked, where every vertex's samples would make rows of millions of pairs.
constexpr double kCoverSpacing = 0.125;

// The samples a cover is first solved on, of `points` (the first `vertices` of them vertices, then
// area samples): where the vertices `spacing` apart (spacing > 0) are fewer than half of them,
// those and every area sample (`spaced_by` = spacing), else every sample (`spaced_by` = 0).
// Indices, ascending.
std::vector<uint32_t> samples_to_cover(const std::vector<Eigen::Vector3d>& points, size_t vertices, double spacing,
                                       double& spaced_by);

// How near a sample its own candidate passes, in parts of the diagonal: float rounding.
constexpr double kTouchSlack = 1e-6;

struct TangentCandidates {
  SphereSet spheres;
  std::vector<uint32_t> touches;  // per sphere: the sample it touches (its index in the samples)
  size_t touching = 0;   // samples that needed a second, smaller ball to be reached
  size_t unreached = 0;  // samples no ball reaches within the slack (a knife edge, a flipped normal)
};

// Candidates at every sample of `surface` (the mesh the samples were drawn on), so that each
// sample is reached by one whatever the field's resolution: the largest inscribed ball tangent
// to the surface there (tangent_ball, inward along the vertex's angle-weighted normal or the
// triangle's), and where a corner of the sample's own faces holds that ball off it by more than
// kTouchSlack of the diagonal, also the largest ball that still reaches it (touching_ball).
// Balls start at `start_radius` (no inscribed ball is larger); an open mesh's radii are also
// bounded by `field` across its holes (options.field_bounds_radius), as every radius is.
TangentCandidates tangent_candidates(const MeshQuery& mesh, const TriMesh& surface, const SurfaceSamples& samples,
                                     const DenseField& field, double start_radius, const CandidateOptions& options);
// The same for the samples `which` alone (indices into `samples`; pose-map's frames offer them
// where nothing else reaches). `field` is needed only where it bounds radii.
TangentCandidates tangent_candidates(const MeshQuery& mesh, const TriMesh& surface, const SurfaceSamples& samples,
                                     const std::vector<uint32_t>& which, const DenseField* field, double start_radius,
                                     const CandidateOptions& options);

// tangent_candidates in two steps (so that sphere-pack's cache can keep the first): each sample's
// of `which` its tangent ball and, where that misses it by more than the slack, the ball that
// touches it (radius 0: none); then the candidates of those balls (`surface`: the samples' mesh,
// whose diagonal sets the slack).
using SampleBalls = std::array<Sphere, 2>;
std::vector<SampleBalls> tangent_balls(const MeshQuery& mesh, const TriMesh& surface, const SurfaceSamples& samples,
                                       const std::vector<uint32_t>& which, const DenseField* field, double start_radius,
                                       const CandidateOptions& options);
TangentCandidates tangent_candidates_of(const std::vector<SampleBalls>& balls, const std::vector<uint32_t>& which,
                                        const SurfaceSamples& samples, const TriMesh& surface);

// Balls through the samples `which` of `samples` (drawn on mesh.surface()): tangent_candidates'
// of each, then, where `nested_down_to` > 0, those nested in each (nested_balls) down to that
// radius: a sphere that keeps one radius over a clip keeps more of a smaller one.
SphereSet balls_through(const MeshQuery& mesh, const SurfaceSamples& samples, const std::vector<uint32_t>& which,
                        const DenseField* field, double start_radius, const CandidateOptions& options,
                        double nested_down_to);
// Balls around the samples `which` (balls_around, within `within` of each) about the axis of
// each one's first ball (tangent_candidates'; none where it has none): where a skinned
// body's skin folds, every ball through a sample is cut in some frame, and a small one beside
// it may stay inside in every frame.
SphereSet balls_around_samples(const MeshQuery& mesh, const SurfaceSamples& samples, const std::vector<uint32_t>& which,
                               const DenseField* field, double start_radius, const CandidateOptions& options,
                               double within);

// The largest radius an inscribed ball of `field`'s solid can have, with a margin for the
// field's own error.
double deepest_radius(const DenseField& field);

}  // namespace spx
