#pragma once
// What sphere-pack's cover chooses from and what it covers: inscribed candidate spheres (centre
// at a near-medial interior voxel, radius the exact distance to the surface, grown to the
// largest inscribed sphere containing it) and surface samples (every vertex plus area samples).
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
// (CoverProblem::merge).
SphereSet inscribed_candidates(const DenseField& field, const MeshQuery& mesh, const CandidateOptions& options);

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

// How near a sample its own candidate passes, in parts of the diagonal: float rounding.
constexpr double kTouchSlack = 1e-6;

struct TangentCandidates {
  SphereSet spheres;
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

// The largest radius an inscribed ball of `field`'s solid can have, with a margin for the
// field's own error.
double deepest_radius(const DenseField& field);

}  // namespace spx
