#pragma once
// A skinned sphere's one radius over the whole clip, not only at the poses the tools were given:
// the rest skinned by the joint matrices of every frame of the clip and half-way between
// (skin.json's clip), each sphere's radius there (exact distance, 0 where its centre is outside),
// the least kept. Between poses another part can sweep through a sphere's place (a leg passing a
// leg): a radius that holds only at the poses then pokes out between them.
#include <string>
#include <vector>

#include "core/log.hpp"
#include "core/sphere.hpp"
#include "io/skin_file.hpp"
#include "mesh/deforming_query.hpp"
#include "mesh/mesh.hpp"
#include "posemap/skinned_map.hpp"

namespace spx {

// Skinned spheres checked at every time of a clip: how many poke out of the body at some time,
// how many centres leave it, and how far past the surface the worst gets (at least; a length).
struct ClipOvershoot {
  size_t times = 0, spheres_out = 0, centres_outside = 0;
  double worst = 0;
};

class ClipRadius {
 public:
  // `skin`'s vertex weights are `rest`'s, one list per vertex. At the clip's times a sphere may
  // poke out by up to `overshoot` (a length; its centre stays inside).
  // `sweep`: false walks every sphere through every time (the reference the tests compare with).
  ClipRadius(const SkinFile& skin, const TriMesh& rest, double max_radius, double overshoot = 0, bool sweep = true);
  size_t time_count() const { return clip_.times.size(); }

  // The least of radius[i] and sphere i's radius (its depth plus the overshoot allowed; 0 where its
  // centre is outside) at every time of the clip, the sphere following
  // influences[i] (its bind point in the asset's space). The times are walked in order, a few
  // skinned at once, so memory stays that of a few meshes; each sphere's search there is bounded
  // by its least radius so far, which for a sphere the time does not shrink visits a few boxes.
  // A closed mesh's hierarchy is refitted to each time (DeformingQuery). Another builds its
  // winding numbers afresh and decides which triangles bound the solid only near the spheres
  // (NearBoundaryQuery, MeshQuery's answers). On a closed mesh a sphere is first asked
  // once per block of times, in the frame of its heaviest joint, where the parts that move
  // rigidly with it stay put: where every triangle stays farther than its radius needs through
  // the block (the sweep for most, then each of the few it finds near, step by step against the
  // centre), the block cannot lower it and its times are not asked (the same radii to the bit).
  // A time asked looks for the surface only as near as the radius needs; where nothing is, and
  // the parts and the centre moved less than twice that since the time before, the centre is
  // still inside without the winding number.
  // Independent of the thread count. With a `log`, a percentage on a terminal (thousands of
  // candidates over a clip take a minute). `tally`: how many of the spheres' blocks were asked
  // and how many of those the sweep settled.
  struct Tally {
    size_t blocks = 0, settled = 0;
  };
  std::vector<double> least(const std::vector<SkinInfluence>& influences, const std::vector<double>& radius,
                            const Log* log = nullptr, Tally* tally = nullptr) const;

  // The rest mesh skinned at clip time k, as pose-extract skins the asset.
  TriMesh mesh_at(size_t k) const;

 private:
  struct Time;  // one time's mesh and what queries it
  // The least of `r` and the radius of a sphere centred at c at that time. `moved`: how far the
  // centre and the farthest vertex went since the time before, where the surface stayed at least
  // r less the overshoot from it (infinite at the clip's first time).
  double least_at(const Time& time, const Eigen::Vector3d& c, double r, double moved) const;
  // The spheres `todo` walk the times from `first` (their meshes `meshes`; `before`, the mesh at
  // time first - 1, none at the first) in order.
  void walk(size_t first, const std::vector<Eigen::Vector3d>* before,
            const std::vector<std::vector<Eigen::Vector3d>>& meshes, const std::vector<uint32_t>& todo,
            const std::vector<SkinInfluence>& influences, std::vector<double>& radius) const;
  // Of `todo`, those the times from `first` (`meshes`) might shrink: the others stay farther from
  // every triangle than their radius needs at every one of them, as the sweep from time
  // `first` - 1 (`before`) in the frame of their heaviest joint bounds it.
  std::vector<uint32_t> unsettled(size_t first, const std::vector<Eigen::Vector3d>& before,
                                  const std::vector<std::vector<Eigen::Vector3d>>& meshes,
                                  const std::vector<uint32_t>& todo, const std::vector<SkinInfluence>& influences,
                                  const std::vector<double>& radius) const;
  double overshoot_ = 0;
  bool sweep_ = true;

  const SkinClip& clip_;
  const TriMesh& rest_;
  double max_radius_;
  double margin_;  // the sweeps' decisions kept off rounding in their sums: a billionth of the diagonal
  SkinnedVertices vertices_;
  DeformingQuery deforming_;
};

// pose-map without --hold-over-clip: the written `spheres` (rest; each following its influence)
// checked at every time of `skin`'s clip, where a host plays them, with a warning where one pokes
// out by more than a thousandth of the diagonal or a centre leaves the body.
ClipOvershoot check_over_clip(const SkinFile& skin, const TriMesh& rest, double max_radius, const SphereSet& spheres,
                              const std::vector<SkinInfluence>& influences, Log& log);

// That warning's text, for `out` on a rest of diagonal `diagonal`: how many poke out and how far,
// how many centres leave the body where any does, and what holds them.
std::string between_poses_warning(const ClipOvershoot& out, size_t sphere_count, double diagonal);

}  // namespace spx
