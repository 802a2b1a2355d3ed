#pragma once
// The tetrahedral mesh of the rest shape that carries the surface motion into the interior.
#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "core/log.hpp"
#include "mesh/mesh.hpp"
#include "mesh/mesh_query.hpp"

namespace spx {

struct TetMesh {
  std::vector<Eigen::Vector3d> vertices;
  std::vector<Eigen::Vector4i> tets;            // positively oriented
  std::vector<Eigen::Vector3i> boundary_faces;  // faces with one tet
  std::vector<int> boundary_face_tet;           // that tet
  std::vector<char> on_boundary;                // per vertex
  // Bodies that bound a solid yet got no tets even at an eighth of the tet size in them (a
  // flap of flipped triangles, a sheet): named ("body 4 of 20 (66 triangles around x, y, z)").
  // Their spheres, if any, follow the tets nearby.
  std::vector<std::string> unmeshed_bodies;
};

struct TetOptions {
  double size = 0;  // target edge length; 0: bounding-box diagonal / 30
  // Ask the winding number's expansions even where the surface is closed (where a ray's count
  // gives the same signs sooner): the reference the ray count is checked against.
  bool winding_expansions = false;
};

// CGAL Mesh_3 on the implicit domain {winding number of `surface` > 1/2}, so open meshes
// and soups mesh too; on a closed surface the winding number is a ray's signed crossing count.
// Sequential and seeded, with no time limit on any step: the same input gives the same tets.
TetMesh tetrahedralize(const TriMesh& surface, const TetOptions& options, Log& log = Log::silent());

// A user tet mesh in MEDIT .mesh format (Vertices + Tetrahedra sections; lines opening with '#'
// are comments).
TetMesh read_medit_tets(const std::string& path);

// A user's tets that do not fit the rest (`rest`: its query; another body's, in another unit, moved) are refused
// (spx::Error naming `path`, exit 2): half their boundary's vertices farther than a twentieth of
// the rest's diagonal from its surface. The map pins each boundary vertex to the surface point
// nearest it, so such tets gave a proxy with no word of why (a tenfold mesh: one blend site).
void check_tets_fit(const TetMesh& tets, const MeshQuery& rest, const std::string& rest_name, const std::string& path);

// pose-map's cache (`--cache DIR`): the rest's tets kept between runs, so that a run with another
// tolerance or budget on the same rest skips Mesh_3 and maps to the same bytes. DIR/tets-KEY.mesh,
// a MEDIT file (read_medit_tets reads it, as other tools do) whose first line names its key and
// whose next ones the bodies that got no tets (a run from the cache reports them too). The key:
// the rest mesh, the tet options, the project's and CGAL's versions and the program's build
// (core/version.hpp: a tool rebuilt from other code meshes afresh).
std::string tets_cache_key(const TriMesh& rest, const TetOptions& options);
std::string tets_cache_file(const std::string& dir, const std::string& key);
// The tets cached at `path` for `key`; none where there is no such file, or one that does not
// read as this key's (cut short, or another's): the tets are then meshed and written again.
std::optional<TetMesh> read_tets_cache(const std::string& path, const std::string& key);
// Writes `tets` to `path` for `key`, atomically.
void write_tets_cache(const std::string& path, const std::string& key, const TetMesh& tets);

// The paper's local blend: each point's site is its nearest tet vertex (brute force, in
// parallel; ties to the lower index). `sites`: those vertices, each once, by index; `of_point`:
// each point's index into them.
struct BlendSites {
  std::vector<Eigen::Vector3d> sites;
  std::vector<int> of_point;
};
BlendSites blend_sites(const TetMesh& tets, const std::vector<Eigen::Vector3d>& points);

}  // namespace spx
