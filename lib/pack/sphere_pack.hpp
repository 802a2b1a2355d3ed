#pragma once
// sphere-pack: the rest-pose spheres S_0 from a signed distance field, by coverage (default) or
// by the paper's greedy packing.
#include "core/json_io.hpp"
#include "core/log.hpp"
#include "core/tolerance.hpp"
#include "pack/cover.hpp"
#include "pack/pack.hpp"

namespace spx {

enum class PackMethod { cover, greedy };

struct SpherePackOptions {
  PackMethod method = PackMethod::cover;
  PackOptions pack;         // radius limits and the budget (pack.max_spheres) for both methods
  Tolerance tolerance;      // the max vertex error asked for (both methods)
  size_t area_samples = 4000;   // cover: surface samples besides every vertex
  size_t max_candidates = 12000;
  uint64_t seed = 1;
};

// The cover method on a field and its mesh: the spheres, and how the cover went.
struct CoverSelection {
  SphereSet spheres;           // largest first
  CoverResult cover;
  Tolerance tolerance;         // the one in force (the default when no size was asked)
  double target = 0;           // the tolerance as a length (0: budget alone)
  std::string limited_by;
  size_t candidates = 0, samples = 0;
  SphereSet pool;              // every candidate (pose-map selects from them over every pose)
};
CoverSelection select_by_cover(const DenseField& field, const MeshQuery& mesh, const SpherePackOptions& options,
                               Log& log = Log::silent());

// sphere-pack IN.vdb -o OUT.spheres.json [--mesh REST] [--tolerance T] [--max-spheres N] [--method M]
void sphere_pack_files(const std::string& input, const std::string& mesh_path, const std::string& output,
                       const SpherePackOptions& options, Log& log, json& report);

}  // namespace spx
