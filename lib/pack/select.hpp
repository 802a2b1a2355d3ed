#pragma once
// The cover method on a field and its mesh, as sphere-pack (and the benchmarks) call it:
// inscribed candidates, surface samples, the set cover for a tolerance or a budget, then the
// centres refined off the grid; and the options sphere-pack's two methods take.
#include <string>

#include "core/log.hpp"
#include "pack/cover.hpp"
#include "pack/pack.hpp"

namespace spx {

enum class PackMethod { cover, greedy };

struct SpherePackOptions {
  PackMethod method = PackMethod::cover;
  PackOptions pack;         // radius limits and the budget (pack.max_spheres) for both methods
  double tolerance = 0;     // the max vertex error asked for, a length (0: none; both methods)
  size_t area_samples = 4000;   // cover: surface samples besides every vertex
  size_t max_candidates = 12000;
  uint64_t seed = 1;
};

// The cover method on a field and its mesh: the spheres, and how the cover went.
struct CoverSelection {
  SphereSet spheres;           // largest first
  CoverResult cover;
  double target = 0;           // the tolerance (0: budget alone)
  Limit limited_by = Limit::tolerance;
  size_t candidates = 0, samples = 0;
  SphereSet pool;              // every candidate (pose-map selects from them over every pose)
};
// Throws OptionError when `options` ask neither a tolerance nor a budget.
CoverSelection select_by_cover(const DenseField& field, const MeshQuery& mesh, const SpherePackOptions& options,
                               Log& log = Log::silent());

}  // namespace spx
