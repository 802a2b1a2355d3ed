#pragma once
// pose-map: S_1..S_e from S_0. Each center moves by the harmonic map f (or by the skin, for a
// rigged body); its radius in pose i is min(max radius, distance to M_i); a center that lands
// outside M_i is reported and its sphere gets radius 0 in that pose. Under joint selection each of those spheres, the rest's
// too, is then grown to the largest inscribed sphere containing it (grow_inscribed), candidates
// and result alike. Each sphere's blend site is its nearest rest tet vertex.
#include <array>
#include <optional>
#include <string>
#include <vector>

#include "core/log.hpp"
#include "mesh/mesh.hpp"
#include "mesh/union_distance.hpp"
#include "io/spheres_file.hpp"
#include "io/proxy_file.hpp"
#include "io/skin_file.hpp"
#include "posemap/blend_hold.hpp"
#include "posemap/clip_radius.hpp"
#include "posemap/joint_selection.hpp"
#include "posemap/tet_mesh.hpp"

namespace spx {

struct PoseInput {
  std::string name, source;
  TriMesh mesh;
};

struct PoseMapOptions {
  TetOptions tets;
  double max_radius = 0;    // 0: the spheres file's
  // Joint selection: no sphere chosen smaller than this at rest (skinned: its one radius);
  // 0: the spheres file's min_radius_asked (sphere-pack's --min-radius), else none.
  double min_radius = 0;
  std::string tet_file;     // use this MEDIT tet mesh instead of meshing
  // A folder the rest's tets (tet_mesh.hpp's cache), each pose's field's depths, voxels and grown
  // candidates (pose_cache.hpp) and a skinned body's carries (carry_cache.hpp) are kept in between
  // runs: read where it holds this rest's and these poses' (the same, so the same proxy), else
  // made and written there. Kept under cache_limit bytes (0: no limit) by removing the folder's
  // cache files least recently used (core/cache_folder.hpp).
  std::string cache_dir;
  uint64_t cache_limit = kDefaultCacheLimit;
  // The paper's future work: pack the part of each pose's interior the mapped spheres leave
  // uncovered, and map the new centers back to the rest pose through the inverse map.
  bool fill_gaps = false;
  double fill_min_radius = 0;   // 0: 3/4 of a voxel of the spheres' field
  // Each pose is filled until its max vertex error is at most this length; 0: the spheres
  // file's tolerance, or else the rest pose's own max error.
  double fill_tolerance = 0;
  size_t fill_max_per_pose = 0; // 0: no limit
  // Joint selection: one sphere set chosen from the spheres file's candidates so that the rest
  // and every pose meet a tolerance (a length), or the least max error over all of them for a
  // budget. With neither, and a file that has candidates, the file's own tolerance and budget
  // are used, or else the default tolerance; `map_given` maps the file's spheres as they are
  // instead (the paper's S_1..S_e).
  double tolerance = 0;
  size_t max_spheres = 0;
  bool map_given = false;
  // Skinned, with the clip in the skin (pose-extract --animation): each sphere's one radius also
  // the least over every frame of the clip and half-way between (posemap/clip_radius.hpp), there
  // its depth plus `clip_overshoot` (a length; at the poses themselves, the depth alone).
  bool hold_over_clip = false;
  double clip_overshoot = 0;
  // Blended examples: each sphere's radii scaled down where it pokes out at the blends a host
  // plays between them (posemap/blend_hold.hpp): every two examples half and half, and with
  // `morph_targets` (the examples are morph targets, which a host adds) two or more at 1 at once.
  bool hold_over_blends = false;
  bool morph_targets = false;
  // Joint selection: each pose's surface samples (their count besides every vertex, their seed)
  // and every vertex from the start (JointSelectionOptions::spaced_vertices off); not given, the
  // spheres file's sampling (sphere-pack's), the defaults for a file without one.
  std::optional<size_t> area_samples;
  std::optional<uint64_t> seed;
  std::optional<bool> every_vertex;
  // Joint selection with a budget: covered and refined again this many times from the refined
  // spheres (JointSelectionOptions::polish_rounds); -1: once, and not at all for a skinned body.
  // Once, not sphere-pack's twice: each round refines over every frame (the walk's 48 frames at
  // 64 spheres: 116 s without, 199 s with one, 311 s with two), and the second lowered fewer of
  // the rows measured than the first. Not on a skinned body: on the walk no round lowered the
  // error over the clip between its frames (docs/pose-map.md, "The polish over every pose").
  int polish_rounds = -1;
};

// Whether pose-map selects one set over every pose (asked, or a spheres file with candidates)
// rather than mapping the file's spheres as given.
inline bool selects_jointly(const PoseMapOptions& opt, const SpheresFile& spheres) {
  return !opt.map_given &&
         (opt.tolerance > 0 || opt.max_spheres > 0 || opt.min_radius > 0 || !spheres.candidates.empty());
}

// The least rest radius the joint selection may choose: asked of pose-map, or else what
// sphere-pack was given (--min-radius), or else none (0).
inline double selection_min_radius(const PoseMapOptions& opt, const SpheresFile& spheres) {
  return opt.min_radius > 0 ? opt.min_radius : spheres.min_radius_asked;
}

// The joint selection's sampling: each part as asked of pose-map, or else the spheres file's.
inline CoverSampling selection_sampling(const PoseMapOptions& opt, const SpheresFile& spheres) {
  return {opt.area_samples.value_or(spheres.sampling.area_samples), opt.seed.value_or(spheres.sampling.seed),
          opt.every_vertex.value_or(spheres.sampling.every_vertex)};
}

// Gap filling (PoseMapOptions::fill_gaps): how far each pose got.
struct GapFilling {
  double min_radius = 0, target = 0;
  struct Pose {
    size_t added = 0, lost_outside_rest = 0;  // spheres added; found in the pose but mapped outside the rest
    bool target_met = false;
    double max_error_reached = 0;
  };
  std::vector<Pose> poses;  // per example pose
  size_t spheres_before = 0, spheres_after = 0;
  std::vector<ErrorStats> errors_before;  // per pose, the rest first
};

// pose-map --cache: one pose's file in the cache folder (posemap/pose_cache.hpp), whether its
// field's depths and voxels were read from it (else built, and written to it), and its own
// candidates read from it and grown here.
struct PoseCacheUse {
  std::string file;  // empty: the pose's field was not asked for
  bool read = false;
  size_t grown_read = 0, grown_made = 0;
};

// What pose-map did besides the proxy, for the tool's report: the tets, the map, each pose's
// radii and error, the joint selection and the gap filling.
struct PoseMapSummary {
  std::string tet_file;  // the user's tets, or empty: CGAL Mesh_3's
  std::string tet_cache;  // the tets' file in the cache folder asked for, or empty
  bool tets_from_cache = false;  // Mesh_3's tets read from it (else meshed, and written to it)
  size_t tet_vertices = 0, tetrahedra = 0, boundary_faces = 0;
  std::vector<std::string> unmeshed_bodies;
  bool skinned = false;  // f is the skin (else the harmonic map)
  // Skinned: times of the clip each radius also holds at (0: the poses alone), and the written
  // spheres whose radius the clip lowered.
  size_t clip_times = 0, clip_shrunk = 0;
  double clip_overshoot = 0;  // how far a sphere may poke out at the clip's times (a length)
  ClipOvershoot between;  // skinned, radii not held over the clip: the spheres at its times (times 0: not checked)
  size_t joints = 0, data_points = 0, dropped_points = 0, centers_outside_tets = 0;
  bool open_solid = false;  // radii also bounded across the holes by each pose's field
  // Per pose, the rest first: spheres of radius 0 by cause (centre outside, hole bound, on the
  // surface, 0 in another pose), and the vertex error.
  std::vector<std::array<size_t, 4>> zero_radius;
  std::vector<ErrorStats> errors;  // on the solid's surface (mesh/solid_boundary.hpp)
  // Per pose: triangles left out as walls inside the solid, and those kept in pieces.
  std::vector<std::pair<size_t, size_t>> walls;
  std::vector<PoseCacheUse> pose_caches;  // per pose, the rest first (empty without --cache)
  // pose-map --cache, skinned: the carries' file (posemap/carry_cache.hpp; empty: none), the
  // candidates' choices read from it and made in this run; with --hold-over-clip, the held
  // radii's likewise.
  struct CacheUse {
    std::string file;
    size_t read = 0, made = 0;
  } carry_cache, held_cache;
  std::optional<CacheTrim> cache_folder;  // with a cache folder: it after this run's files were written
  std::optional<JointSelection> selection;  // when selected jointly
  double selection_target = 0;              // its tolerance (a length; 0: a budget alone)
  double selection_min_radius = 0;          // the least rest radius it could choose (0: none)
  CoverSampling selection_sampling;         // each pose's samples it drew
  std::optional<GapFilling> fill;           // when asked
  std::optional<BlendHold> blend_hold;      // when asked
};

struct PoseMapResult {
  ProxyModel proxy;
  PoseMapSummary summary;
};

// `skin` (the poses' rig, its poses in the order of `poses`; null: none) makes f the skin: each
// sphere follows it (posemap/skinned_map.hpp) and keeps one radius, the least over the rest and
// every pose, so that the host can skin it through any frame; the proxy gets its skin.
PoseMapResult pose_map(const TriMesh& rest, const std::string& rest_source, const std::vector<PoseInput>& poses,
                       const SpheresFile& spheres, const PoseMapOptions& options, Log& log = Log::silent(),
                       const SkinFile* skin = nullptr);

}  // namespace spx
