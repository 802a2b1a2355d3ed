#pragma once
// pose-map: S_1..S_e from S_0. Each center moves by the harmonic map f (or by the skin, for a
// rigged body); its radius in pose i is min(max radius, distance to M_i); a center that lands
// outside M_i is reported and its sphere gets radius 0 in that pose. Under joint selection each of those spheres, the rest's
// too, is then grown to the largest inscribed sphere containing it (grow_inscribed), candidates
// and result alike. Each sphere's blend site is its nearest rest tet vertex.
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/log.hpp"
#include "core/tolerance.hpp"
#include "mesh/mesh.hpp"
#include "io/spheres_file.hpp"
#include "io/proxy_file.hpp"
#include "io/skin_file.hpp"
#include "posemap/tet_mesh.hpp"

namespace spx {

struct PoseInput {
  std::string name, source;
  TriMesh mesh;
};

struct PoseMapOptions {
  TetOptions tets;
  double max_radius = 0;    // 0: the spheres file's
  std::string tet_file;     // use this MEDIT tet mesh instead of meshing
  // The paper's future work: pack the part of each pose's interior the mapped spheres leave
  // uncovered, and map the new centers back to the rest pose through the inverse map.
  bool fill_gaps = false;
  double fill_min_radius = 0;   // 0: 3/4 of a voxel of the spheres' field
  // Each pose is filled until its max vertex error is at most this; 0: the spheres file's
  // tolerance, or else the rest pose's own max error.
  Tolerance fill_tolerance;
  size_t fill_max_per_pose = 0; // 0: no limit
  // Joint selection: one sphere set chosen from the spheres file's candidates so that the rest
  // and every pose meet a tolerance (or the least max error over all of them for a budget).
  // With neither, and a file that has candidates, the file's own tolerance (or 2%) is used;
  // `map_given` maps the file's spheres as they are instead (the paper's S_1..S_e).
  Tolerance tolerance;
  size_t max_spheres = 0;
  bool map_given = false;
  size_t area_samples = 4000;
  uint64_t seed = 1;
};

struct PoseMapResult {
  ProxyModel proxy;
  nlohmann::json report;  // tets, map, per-pose errors and outside centers
};

// `skin` (the poses' rig, its poses in the order of `poses`; null: none) makes f the skin: each
// sphere follows it (posemap/skinned_map.hpp) and keeps one radius, the least over the rest and
// every pose, so that the host can skin it through any frame; the proxy gets its skin.
PoseMapResult pose_map(const TriMesh& rest, const std::string& rest_source, const std::vector<PoseInput>& poses,
                       const SpheresFile& spheres, const PoseMapOptions& options, Log& log = Log::silent(),
                       const SkinFile* skin = nullptr);

}  // namespace spx
