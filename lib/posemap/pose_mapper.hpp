#pragma once
// Inside pose_map() (posemap.hpp says what it does): its steps and the state they share.
// posemap.cpp takes the steps in order (the tets and the map, the poses' solids, the spheres
// mapped, gap filling, the summary); pose_spheres.cpp carries spheres into the poses, offers a
// pose's own candidates, maps them back to the rest and shows the poses to the joint selection.
#include <Eigen/Core>
#include <array>
#include <atomic>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/log.hpp"
#include "mesh/defects.hpp"
#include "mesh/deforming_query.hpp"
#include "mesh/mesh.hpp"
#include "mesh/mesh_query.hpp"
#include "pack/candidates.hpp"
#include "pack/pack.hpp"
#include "posemap/carry_cache.hpp"
#include "posemap/harmonic_map.hpp"
#include "posemap/pose_solid.hpp"
#include "posemap/posemap.hpp"
#include "posemap/skinned_map.hpp"
#include "sdf/sdf.hpp"

namespace spx {
class SelectionFrames;
}

namespace spx::detail {

// pose-map's steps, in the order pose_map() takes them, and the state they share: the tets and
// the map f, each pose's tet vertices and solid, and the proxy as it grows.
class PoseMapper {
 public:
  PoseMapper(const TriMesh& rest, const std::string& rest_source, const std::vector<PoseInput>& poses,
             const SpheresFile& spheres, const PoseMapOptions& opt, const SkinFile* skin, ProxyModel& proxy, Log& log)
      : rest_(rest), rest_source_(rest_source), poses_(poses), spheres_(spheres), opt_(opt), skin_(skin), proxy_(proxy),
        log_(log), open_solid_(!find_defects(rest).watertight()) {}

  // A closed body's poses face outward as its rest does (spheres_fit.hpp): asked before the tets,
  // so that an inside-out pose fails at once.
  void check_poses_face_outward() const;

  // The spheres file's spheres fit the rest mesh (spheres_fit.hpp): asked before the tets, so that
  // another asset's rest mesh, or a pose given as the rest, fails at once and not after Mesh_3.
  void check_rest_fits_spheres();

  // The tets cache (PoseMapOptions::cache_dir) read, before any work: a folder that cannot be
  // made fails at once.
  void read_cached_tets();

  // The paper's tet mesh of M_0: CGAL Mesh_3 (or the cache's), or the user's.
  void make_tets();

  // f: the surface motion of every pose carried to the tet vertices; for a rigged body the skin,
  // its weights carried in by the same extension, and the tets skinned (for the inverse map).
  void solve_map();

  // Each pose's solid, the rest's included: exact distances and, for open meshes (whose solid
  // also ends across the holes, where there are no triangles), the pose's own field at the
  // spheres' voxel size. One rule then sets every radius. Needs the poses alone, not the tets.
  void build_solids(Log& log);
  // Not skinned, under the joint selection: the own candidates of the poses its first round
  // selects on, listed while Mesh_3 keeps the other core (the same lists as when first asked),
  // up to the first pose that would start after the tets are done.
  void list_pose_candidates_beside_tets(Log& log);

  // The joint selection runs (rather than the file's spheres mapped as given).
  bool selects_jointly() const;

  // One sphere set for the rest and every pose (posemap/joint_selection.hpp), recorded in the
  // summary. Returns the chosen candidates (rest pose).
  SphereSet select_jointly(const SphereSet& file_candidates, PoseMapSummary& summary);

  // S_1..S_e: appends rest spheres to every pose, centers through f, and in every pose (the
  // rest too) the radius by the one rule of PoseSolid.
  void map_spheres(const SphereSet& rest_spheres);

  // Skinned: the spheres just mapped (from `first`) keep their one radius over the whole clip,
  // in every pose (as the selection held its candidates: the same radii, bit for bit).
  void hold_over_clip(size_t first, size_t n, std::vector<std::vector<char>>& cause);

  // --hold-over-blends: the written spheres' radii scaled down where they poke out at the blends
  // between the examples (posemap/blend_hold.hpp).
  BlendHold hold_over_blends();

  // The paper's future work: pack what each pose's mapped spheres leave uncovered, and map the
  // new spheres back to the rest pose through the inverse map.
  GapFilling fill_gaps();

  // Blend sites: the nearest rest tet vertex of each sphere (the paper's local blend).
  void assign_blend_sites();

  // A rigged body's proxy carries each sphere's influence and its one radius.
  void attach_skin();

  // Skinned, radii not held over the clip: the spheres checked at its other times, which a host
  // plays (the poses given say nothing of them).
  void check_between_poses(PoseMapSummary& out) const;

  // The poses', the carries' and the held radii's caches (posemap/pose_cache.hpp, carry_cache.hpp)
  // written where this run added to them; a file that cannot be written is a warning (the proxy
  // does not need it).
  void save_caches();
  // Then the cache folder kept under its limit, this run's files (the tets' too) kept.
  void trim_cache(PoseMapSummary& out);

  // Warnings for every radius 0, and the summary's tets, map, per-pose errors and zero radii.
  void summarize(PoseMapSummary& out) const;

 private:
  // The tolerance (as a length, 0: none) and budget asked here, or else what sphere-pack was
  // asked, or else the default tolerance.
  std::pair<double, size_t> selection_size() const;
  // Of the vertices past `target` from `chosen` in their pose, those with no solid beside them
  // (an open body's parts that enclose nothing there: no field reaches them).
  size_t vertices_with_no_solid(const SelectionFrames& frames, const SphereSet& chosen, double target) const;

  // The map as the joint selection sees it.
  class Frames;

  std::string proxy_pose_name(size_t f) const { return f == 0 ? stem_of(rest_source_) : poses_[f - 1].name; }

  // Not skinned: rest spheres carried into frame f (0: the rest) by in_pose.
  SphereSet carry(const SphereSet& rest, size_t f) const;

  // The same spheres, bit for bit (the selection's set at rest against the file's candidates).
  static bool same_spheres(const SphereSet& a, const SphereSet& b);

  // Not skinned: rest center c (at `at` in the tets) in pose i (0: the rest): its center through
  // f, its radius by the pose's rule (then grown, under joint selection), and why it is 0 if it is.
  std::pair<Sphere, PoseSolid::Zero> in_pose(const Eigen::Vector3d& c, const TetLocator::Location& at, size_t i,
                                             bool cause) const;

  // The spheres a rest center c becomes in every pose (0: the rest), each by in_pose; a skinned
  // sphere keeps the least of its radii in every pose.
  std::vector<std::pair<Sphere, PoseSolid::Zero>> in_poses(const Eigen::Vector3d& c, bool cause,
                                                           SkinInfluence* followed) const;

  // Packing in a pose's own field: the proxy's max radius, and the field bounding radii across
  // an open mesh's holes.
  PackOptions pose_pack_options() const;

  // Pose i's own field (0: the rest) at the spheres' voxel size, built once when first asked.
  // `inside_only`: for the inside's depths and medial voxels alone (released before other use).
  const DenseField& pose_field(size_t i, bool inside_only = false);
  // An open mesh's fields bound every radius to the end; otherwise each is asked once (a skinned
  // body's floors are kept as its depths).
  void release_field(size_t i);

  SdfOptions field_options(bool inside_only = false) const;

  // Skinned: rest centres carried into every pose (SkinnedMap::carry), their choices through
  // the carries' cache where there is one.
  SkinnedMap::Carried carry_skinned(const SphereSet& rest);
  // Skinned, with a clip: each radius held over it (ClipRadius::least), through the held radii's
  // cache where there is one.
  std::vector<double> held_over_clip(const std::vector<SkinInfluence>& influences, const std::vector<double>& radii);
  // What a skinned choice depends on, hashed (carry_cache.hpp); `held`: and a radius held over
  // the clip.
  std::string carry_cache_key(bool held) const;

  // Pose i's depths (`skinned`) and own candidates' voxels from the cache, where it holds them
  // (pose_cache.hpp): then no field is built for it.
  bool pose_from_cache(size_t i, bool skinned);

  std::vector<ErrorStats> pose_errors() const;

  // Pose i's own inscribed candidates that come within `reach` of any of `points` (samples of
  // that pose no mapped candidate reaches) and were not offered before, in pose coordinates.
  SphereSet pose_candidates_near(size_t i, const std::vector<Eigen::Vector3d>& points, double reach);
  // Pose i's own candidates, listed from the cache or its field when first asked.
  CandidatesOnDemand& pose_inscribed(size_t i);

  // Through the inverse map (barycentric in pose i's deformed tets); those that land outside
  // the rest are counted in `lost`. Without `radii` (skinned candidates, whose carry finds each
  // radius over the clip from the centre alone) every radius is 0.
  SphereSet map_back_to_rest(size_t i, const SphereSet& in_pose, size_t* lost = nullptr, bool radii = true) const;

  const TriMesh& rest_;
  const std::string& rest_source_;
  const std::vector<PoseInput>& poses_;
  const SpheresFile& spheres_;
  const PoseMapOptions& opt_;
  const SkinFile* skin_;  // the poses' rig, or null
  ProxyModel& proxy_;
  Log& log_;
  TetMesh tets_;
  std::atomic<bool> tets_done_{false};  // list_pose_candidates_beside_tets starts no pose after it
  std::string tet_cache_key_, tet_cache_file_;  // what the tets cache is asked for, and where
  std::optional<TetMesh> cached_tets_;  // the cache's, where it held this rest's
  std::unique_ptr<HarmonicMap> f_;
  std::unique_ptr<SkinnedMap> skinned_;  // f for a rigged body
  std::vector<SkinInfluence> influences_;  // skinned: the influence each written sphere follows
  std::unique_ptr<ClipRadius> clip_;     // its clip between the poses, where the skin has it
  size_t clip_shrunk_ = 0;               // written spheres the clip shrank
  std::vector<std::vector<Eigen::Vector3d>> deformed_;  // per pose: tet vertices
  std::vector<const TriMesh*> meshes_;                  // rest, then the poses
  std::vector<std::unique_ptr<MeshQuery>> queries_;
  bool open_solid_;  // the rest is not watertight: fields bound radii across its holes
  std::vector<std::unique_ptr<DenseField>> fields_;  // per pose, built when first asked
  std::vector<DepthField> depths_;                   // skinned, per pose: its field's depths (floors)
  std::vector<PoseSolid> solids_;
  std::unique_ptr<DeformingQuery> deforming_;    // skinned, closed: one hierarchy refitted to each frame
  std::vector<DeformingQuery::Shape> shapes_;
  std::vector<std::unique_ptr<CandidatesOnDemand>> pose_inscribed_;  // per pose: its own candidates
  std::vector<PoseCacheUse> pose_cache_;  // per pose, the rest first: its file in the cache folder, if asked
  std::vector<std::string> pose_cache_key_;
  std::unique_ptr<CarryCache> carry_cache_;  // skinned, with a cache folder: made at the first carry
  std::unique_ptr<HeldCache> held_cache_;    // and held over the clip: made at the first hold
  std::vector<Eigen::Vector3d> rest_centers_;            // for the blend sites
  std::vector<std::array<size_t, 4>> zero_radius_;       // per pose, by cause
  bool grow_ = false;                                    // spheres grown in every pose (joint selection)
  std::optional<SphereSet> rest_grown_;                  // the file's candidates carried into the rest (grown)
};

}  // namespace spx::detail
