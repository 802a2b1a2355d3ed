#pragma once
// sphere-pack: the greedy packing of the paper (after Budsberg et al. 2014). Each sphere is
// centered at the deepest voxel left, with radius min(max radius, distance to the surface);
// the field inside it is cleared to 0; repeat until the min radius or the max count.
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/log.hpp"
#include "core/sphere.hpp"
#include "mesh/mesh_query.hpp"
#include "io/dense_field.hpp"

namespace spx {

struct PackOptions {
  double min_radius = 0;  // 0: 1.5 voxels
  double max_radius = std::numeric_limits<double>::infinity();
  size_t max_spheres = 0;  // 0: no limit
  // With a mesh: move each center off the voxel grid (within half a voxel) to where the exact
  // distance to the surface is larger, so each sphere grows.
  bool refine_centers = true;
  // The field bounds radii too (an open mesh's solid ends across its holes, where the mesh has
  // no triangles to measure to); centers then stay on the grid.
  bool field_bounds_radius = false;
};

struct PackStats {
  std::string radius_source;  // "mesh" (exact distance) or "field"
  std::string stop_reason;
  // stop_reason names a limit ("max_spheres", "the field's resolution ..."), not an event or the
  // tolerance met: the tools' last line says "limited by" before it.
  bool stop_is_limit = false;
  double min_radius = 0, max_radius = 0;  // the limits in force
  double smallest = 0, largest = 0;       // radii produced
  double max_error = -1;                  // at the mesh's vertices, where measured (< 0: not)
  bool met_tolerance = false;             // a tolerance was asked (or the default) and met
  size_t interior_voxels = 0, centers_rejected = 0, centers_refined = 0;
  nlohmann::json to_json() const;
  // smallest and largest from the radii of `spheres` (left at 0 when there are none).
  void set_radius_range(const SphereSet& spheres);
};

// Sets to 0 (no longer a candidate centre) every negative value whose voxel centre lies in the
// sphere: what packing does after placing a sphere, and what gap filling does for the spheres
// a pose already has.
void clear_inside(GridVector<float>& values, const GridShape& shape, const Eigen::Vector3d& center, double radius);

struct PackResult {
  SphereSet spheres;
  PackStats stats;
};

// A sphere this small a share of the diagonal is no collider a host can use (0.2 mm on a 2 m
// body): a sharp tip's or a fold's own ball, which a cover keeps where it is the nearest.
constexpr double kTinyRadiusShare = 1e-4;

// Warns of the radii (each sphere's largest) under kTinyRadiusShare of `diagonal`: how many, the
// least, and that --min-radius keeps them out (`where`: whose --min-radius). Returns the report's
// {"count", "below"}.
nlohmann::json warn_tiny_spheres(const std::vector<double>& radii, double diagonal, const std::string& where, Log& log);

// Usage errors for a negative or non-finite min radius, a max radius that is not positive or
// below the min radius (`default_min_radius` where none is given).
void check_radius_limits(const PackOptions& options, double default_min_radius);

// `mesh` (optional) gives exact radii and a robust inside test; without it the field's own
// values are the radii.
PackResult pack_spheres(const DenseField& field, const PackOptions& options, const MeshQuery* mesh,
                        Log& log = Log::silent());

// Tolerance-driven sizing. The greedy order does not depend on the min radius or the count,
// and every vertex's distance to the union only falls as spheres are added, so the fewest
// spheres whose max vertex error is at most `tolerance` is the shortest prefix that meets it.
struct ToleranceResult {
  size_t count = 0;         // spheres to keep
  double max_error = 0;     // rest-pose max vertex error with them
  bool met = false;
  std::vector<double> max_error_by_count;  // [k-1]: max error with the first k spheres
};
// `base` spheres are already in the union (gap filling adds to what a pose has).
ToleranceResult fewest_spheres_within(const TriMesh& mesh, const SphereSet& sequence, double tolerance,
                                      const SphereSet& base = {});

}  // namespace spx
