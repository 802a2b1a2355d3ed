#pragma once
// The cover method on a field and its mesh, as sphere-pack (and the benchmarks) call it:
// inscribed candidates, surface samples, the set cover for a tolerance or a budget, then the
// centres refined off the grid; and the options sphere-pack's two methods take.
#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "core/cache_folder.hpp"
#include "core/log.hpp"
#include "io/spheres_file.hpp"
#include "pack/cover.hpp"
#include "pack/pack.hpp"

namespace spx {

enum class PackMethod { cover, greedy };

// With a candidate at every sample, a cover at delta chooses among those that no other nearly
// contains, within this part of delta (CoverProblem::merge): the rows stay few at large deltas.
constexpr double kCandidateMerge = 0.02;

struct SpherePackOptions {
  PackMethod method = PackMethod::cover;
  PackOptions pack;         // radius limits and the budget (pack.max_spheres) for both methods
  double tolerance = 0;     // the max vertex error asked for, a length (0: none; both methods)
  size_t area_samples = kDefaultAreaSamples;  // cover: surface samples besides every vertex
  bool tangent_candidates = true;  // cover: one candidate tangent at every sample besides the voxels'
  uint64_t seed = 1;
  // Cover: a mesh whose vertices lie much closer together than the delta is covered on vertices
  // an eighth of it apart first, then checked at every vertex (select.cpp); false: every vertex
  // from the start (the tests compare the two).
  bool spaced_vertices = true;
  // Cover, budget mode: the refined spheres join the candidates, and the budget is covered and
  // refined again this many times; a set with no higher max vertex error and a lower product of
  // max and median is kept (select.cpp).
  int polish_rounds = 2;
  // Cover: a folder the candidates no tolerance or budget changes are kept in between runs
  // (pack/candidate_cache.hpp); empty: none. Kept under cache_limit bytes (0: no limit) by
  // removing the folder's cache files least recently used (core/cache_folder.hpp).
  std::string cache_dir;
  uint64_t cache_limit = kDefaultCacheLimit;
};

// The cover method on a field and its mesh: the spheres, and how the cover went.
struct CoverSelection {
  SphereSet spheres;           // largest first
  CoverResult cover;
  double target = 0;           // the tolerance (0: budget alone)
  Limit limited_by = Limit::tolerance;
  size_t candidates = 0, samples = 0;
  // The samples the cover was solved on: every one, or on vertices much closer together than the
  // delta the spaced vertices, those the cover left bare (spaced_joined) and the area samples.
  size_t cover_samples = 0, spaced_joined = 0;
  double vertex_spacing = 0;  // how far apart those vertices were spaced (0: every vertex)
  size_t voxel_candidates = 0;   // candidates [0, voxel_candidates) from the field's voxels, the rest tangent at samples
  size_t touching_samples = 0;   // samples whose tangent ball misses them, given a touching ball too
  size_t unreached_samples = 0;  // samples no candidate of theirs reaches (knife edges, flipped normals)
  size_t chosen_tangent = 0;     // chosen spheres that came from tangent candidates
  size_t chosen_refined = 0;     // polished: chosen spheres that an earlier refinement placed
  size_t polished = 0;           // budget mode: the polish round whose set was kept (0: the first refinement's)
  size_t out_of_reach_added = 0;  // spheres that bring the samples out of reach as near as any candidate comes
  SphereSet offered;           // every candidate
  SphereSet pool;              // the voxels' candidates and the chosen tangent ones (pose-map selects from them over every pose)
  // SpherePackOptions::cache_dir: its file, whether the voxel candidates came from it, and how
  // many samples' balls it gave and how many were made (then kept in it).
  struct Cache {
    std::string file;
    bool voxels_read = false;
    size_t balls_read = 0, balls_made = 0;
    CacheTrim folder;  // the folder after this run's file was written
  };
  std::optional<Cache> cache;
};
// The samples' gaps to the union of `spheres`: the median and max of the first `weighted` (the
// vertices, where the error is measured) and the largest of all (what a cover's delta must reach).
struct UnionGaps {
  double median = 0, max = 0, largest = 0;
};
UnionGaps union_gaps(const std::vector<Eigen::Vector3d>& samples, size_t weighted, const SphereSet& spheres);
// Whether budget mode's polish keeps set a over the best so far, b: its max no higher, and its
// max times its median lower (a lower max bought with a median that rises more, in proportion,
// is not kept; nor is a lower median at a higher max).
bool kept_over(const UnionGaps& a, const UnionGaps& b);

// Throws OptionError when `options` ask neither a tolerance nor a budget.
CoverSelection select_by_cover(const DenseField& field, const MeshQuery& mesh, const SpherePackOptions& options,
                               Log& log = Log::silent());

}  // namespace spx
