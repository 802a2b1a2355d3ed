#pragma once
// A skinned sphere's one radius over the whole clip, not only at the poses the tools were given:
// the rest skinned by the joint matrices of every frame of the clip and half-way between
// (skin.json's clip), each sphere's radius there (exact distance, 0 where its centre is outside),
// the least kept. Between poses another part can sweep through a sphere's place (a leg passing a
// leg): a radius that holds only at the poses then pokes out between them.
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
  ClipRadius(const SkinFile& skin, const TriMesh& rest, double max_radius, double overshoot = 0);
  size_t time_count() const { return clip_.times.size(); }

  // The least of radius[i] and sphere i's radius (its depth plus the overshoot allowed; 0 where its
  // centre is outside) at every time of the clip, the sphere following
  // influences[i] (its bind point in the asset's space). The times are walked in order, a few
  // skinned at once, so memory stays that of a few meshes; each sphere's search there is bounded
  // by its least radius so far, which for a sphere the time does not shrink visits a few boxes.
  // A closed mesh's hierarchy is refitted to each time (DeformingQuery), another is queried
  // afresh (MeshQuery, winding numbers: far slower). Independent of the thread count. With a
  // `log`, a percentage on a terminal (thousands of candidates over a clip take a minute).
  std::vector<double> least(const std::vector<SkinInfluence>& influences, const std::vector<double>& radius,
                            const Log* log = nullptr) const;

  // The rest mesh skinned at clip time k, as pose-extract skins the asset.
  TriMesh mesh_at(size_t k) const;

 private:
  struct Time;  // one time's mesh and what queries it
  // The least of `r` and the radius of a sphere centred at c at that time.
  double least_at(const Time& time, const Eigen::Vector3d& c, double r) const;
  double overshoot_ = 0;

  const SkinClip& clip_;
  const TriMesh& rest_;
  double max_radius_;
  SkinnedVertices vertices_;
  DeformingQuery deforming_;
};

// pose-map without --hold-over-clip: the written `spheres` (rest; each following its influence)
// checked at every time of `skin`'s clip, where a host plays them, with a warning where one pokes
// out by more than a thousandth of the diagonal or a centre leaves the body.
ClipOvershoot check_over_clip(const SkinFile& skin, const TriMesh& rest, double max_radius, const SphereSet& spheres,
                              const std::vector<SkinInfluence>& influences, Log& log);

}  // namespace spx
