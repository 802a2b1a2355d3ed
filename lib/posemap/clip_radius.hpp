#pragma once
// A skinned sphere's one radius over the whole clip, not only at the poses the tools were given:
// the rest skinned by the joint matrices of every frame of the clip and half-way between
// (skin.json's clip), each sphere's radius there (exact distance, 0 where its centre is outside),
// the least kept. Between poses another part can sweep through a sphere's place (a leg passing a
// leg): a radius that holds only at the poses then pokes out between them.
#include <vector>

#include "io/skin_file.hpp"
#include "mesh/deforming_query.hpp"
#include "mesh/mesh.hpp"
#include "posemap/skinned_map.hpp"

namespace spx {

class ClipRadius {
 public:
  // `skin`'s vertex weights are `rest`'s, one list per vertex.
  ClipRadius(const SkinFile& skin, const TriMesh& rest, double max_radius);
  size_t time_count() const { return clip_.times.size(); }

  // The least of radius[i] and sphere i's radius at every time of the clip, the sphere following
  // influences[i] (its bind point in the asset's space). Frames are skinned one at a time (two
  // threads), so memory stays that of two meshes; a closed mesh's hierarchy is refitted to each
  // (DeformingQuery), another is queried afresh (MeshQuery, winding numbers: far slower).
  std::vector<double> least(const std::vector<SkinInfluence>& influences, const std::vector<double>& radius) const;

  // The rest mesh skinned at clip time k, as pose-extract skins the asset.
  TriMesh mesh_at(size_t k) const;

 private:
  // Sphere i's radius at time k, for every sphere whose radius is positive (else 0).
  std::vector<double> radii_at(size_t k, const std::vector<SkinInfluence>& influences,
                               const std::vector<double>& radius) const;


  const SkinClip& clip_;
  const TriMesh& rest_;
  double max_radius_;
  SkinnedVertices vertices_;
  DeformingQuery deforming_;
};

}  // namespace spx
