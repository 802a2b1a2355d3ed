#pragma once
// OUT.spheres.json: the rest-pose sphere set S_0 (schemas/spheres.schema.json).
#include <cstdint>
#include <limits>
#include <string>

#include "core/json_io.hpp"
#include "core/sphere.hpp"

namespace spx {

// The cover's surface samples besides every vertex, in sphere-pack and in each pose for pose-map.
constexpr size_t kDefaultAreaSamples = 4000;

// The cover's surface samples as sphere-pack drew them (--samples, --seed, --every-vertex);
// pose-map's selection draws each pose's the same way unless given its own.
struct CoverSampling {
  size_t area_samples = kDefaultAreaSamples;
  uint64_t seed = 1;
  bool every_vertex = false;  // every vertex from the start (else spaced first, then checked)
  bool is_default() const { return area_samples == kDefaultAreaSamples && seed == 1 && !every_vertex; }
};

struct SpheresFile {
  SphereSet spheres;
  double voxel_size = 0;
  double min_radius = 0;        // the least radius in force: --min-radius, or else the smallest written
  double min_radius_asked = 0;  // --min-radius as given to sphere-pack (0: none); pose-map's selection keeps to it
  double max_radius = std::numeric_limits<double>::infinity();
  std::string radius_source;  // "mesh" or "field"
  double tolerance = 0;       // the rest-pose max error sphere-pack was asked for (0: none)
  size_t max_spheres = 0;     // the sphere budget it was given (0: none)
  CoverSampling sampling;     // the cover method's (written where not the defaults)
  std::string sdf, mesh;      // inputs, as named on the command line
  // The cover method's inscribed candidates (rest pose): pose-map selects from them jointly
  // over every pose. Empty for the greedy method.
  SphereSet candidates;
};

json spheres_to_json(const SpheresFile& file);
SpheresFile read_spheres_file(const std::string& path);
SpheresFile spheres_from_json(const json& j, const std::string& path);

// [[x,y,z,r], ...] <-> spheres; the reader checks every number.
json sphere_array_to_json(const SphereSet& spheres);
SphereSet sphere_array_from_json(const json& array, const std::string& what, const std::string& file,
                                 bool allow_zero_radius);

}  // namespace spx
