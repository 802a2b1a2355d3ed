#pragma once
// Triangle meshes as the tools see them: welded vertices, triangles, and how a pose file
// lines up with the rest mesh it claims to deform.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "core/log.hpp"
#include "mesh/triangulation.hpp"

namespace spx {

struct TriMesh {
  std::vector<Eigen::Vector3d> vertices;
  std::vector<Eigen::Vector3i> triangles;

  Eigen::AlignedBox3d bounds() const;
  double diagonal() const { return bounds().diagonal().norm(); }
};

// Triangles that repeat an earlier triangle's corners in the same turn: a part placed twice in one
// place (a copy left where it was made in a modelling tool, a skinned mesh two nodes place), or
// faces doubled. As a surface each is the one already there; kept, every edge of theirs would
// meet four triangles and the body would read as not watertight (and pack worse).
// And a closed part given both ways (each face also in the other turn: a double-sided export):
// its two sides cancel, the winding number is 0 within it and it would enclose nothing, so its
// inner side (the faces whose turn gives the part a negative volume) is dropped.
struct RepeatedTriangles {
  size_t count = 0;
  Eigen::Vector3d first_at = Eigen::Vector3d::Zero();  // the first one's first corner
  size_t inner_sides = 0;                              // triangles dropped as a part's inner side
  size_t double_sided_parts = 0;
  Eigen::Vector3d inner_first_at = Eigen::Vector3d::Zero();  // the first such part's first corner
  void add(const RepeatedTriangles& more) {
    if (count == 0 && more.count > 0) first_at = more.first_at;
    count += more.count;
    if (inner_sides == 0 && more.inner_sides > 0) inner_first_at = more.inner_first_at;
    inner_sides += more.inner_sides;
    double_sided_parts += more.double_sided_parts;
  }
};

// Morph targets a file weighs in by default (glTF's mesh or node `weights`), which a reader of
// the stored positions leaves at 0: how many (by name), and the first with its weight.
struct DefaultWeights {
  size_t targets = 0;
  std::string first;
  double weight = 0;
};

// A mesh as loaded from a file, with what the weld did, so that poses can be checked
// against exactly the same vertex layout.
struct LoadedMesh {
  std::string path;
  TriMesh mesh;
  std::vector<int> weld;                       // file vertex -> mesh vertex
  std::vector<Eigen::Vector3i> file_triangles; // triangles in file vertex indices
  Triangulation triangulation;                 // how its polygons were split: its poses' are split so
  FannedPolygons fanned;                       // polygons that cross themselves, split as fans
  size_t points_and_lines = 0;                 // faces of 1 or 2 corners in the file, left out
  RepeatedTriangles repeated;                  // read once (read_triangles_once)
  DefaultWeights default_weights;              // morph targets weighed in by default, read at 0
  size_t file_vertex_count() const { return weld.size(); }
  // File vertices merged into another at the same position (face corners, for OBJ through
  // assimp): not the mesh's vertex count, which is mesh.vertices.size().
  size_t merged_corners() const { return weld.size() - mesh.vertices.size(); }
};

// Any format assimp reads (OBJ, PLY, STL, OFF, glTF/GLB, FBX, ...). Coincident vertices are
// welded (seams in glTF, corners unrolled by the OBJ reader), and triangles that then repeat
// another's corners are read once, and a closed part given both ways keeps its outer side
// (`repeated`). Throws spx::Error naming `path`.
LoadedMesh load_mesh(const std::string& path);

// A file assimp can try: it exists, is not a folder, is not empty, and has an extension assimp
// reads. `kind` names it in messages ("a mesh": "is a directory, not a mesh file", "unknown mesh
// format"); `formats` lists what to use instead. Throws spx::Error naming `path` (exit 2 or 3).
void check_importable(const std::string& path, const std::string& kind, const std::string& formats);

// A pose of `rest`: same file layout, positions from `path`. Throws spx::Error (exit 2) when
// the triangle list or vertex count differs from the rest mesh.
TriMesh load_pose(const std::string& path, const LoadedMesh& rest);
// load_pose for each of `paths`, side by side; a failure is reported as the first failing file
// in the given order would be, so the message does not depend on the threads.
std::vector<TriMesh> load_poses(const std::vector<std::string>& paths, const LoadedMesh& rest);

// Coincident positions become one vertex of `welded` (appended), numbered in order of first
// appearance; returns the vertex each position became. -0 and +0 weld together.
std::vector<int> weld_by_position(const std::vector<Eigen::Vector3d>& positions, std::vector<Eigen::Vector3d>& welded);

// Removes from `mesh.triangles` each that repeats an earlier one's corners in the same turn (a
// rotation of them: (b, c, a) repeats (a, b, c)), keeping the first of each, in order. The same
// corners in the other turn are kept: the wall two parts touching face to face share (each part's
// own face: dropped, the union would open there), or a sheet's two sides.
RepeatedTriangles drop_repeated_triangles(TriMesh& mesh);
// Removes the inner side of each closed part given both ways: a part (triangles joined by their
// edges) each of whose triangles has its twin in the other turn, whose one side is a closed,
// consistently oriented surface of nonzero volume. Of each twin the one facing out is kept, in
// order. Any other part is left as it is: a wall two parts touching face to face share, or an
// open sheet's two sides. Returns the counts in `inner_sides` and `double_sided_parts`.
RepeatedTriangles drop_inner_sides(TriMesh& mesh);
// Both, in that order: what the tools read once of a welded mesh.
RepeatedTriangles read_triangles_once(TriMesh& mesh);

// How far a vertex read from a mesh file may lie from the file's own: every reader (assimp's, for
// every format) reads single precision, so up to half the spacing of floats at the mesh's largest
// coordinate. A mesh far from the origin for its size is read coarser than it was written.
double read_rounding(const TriMesh& mesh);
// `mesh`, read from `file`, against the field that follows it (`voxel`): read coarser than a voxel
// it is refused (spx::Error, exit 2, naming the file: the field would follow the reading, not the
// file), past a tenth of one a warning. Each says to move the mesh near the origin.
void check_read_rounding(const TriMesh& mesh, double voxel, const std::string& file, Log& log);

// Warns, naming `file`, of the polygons its reading split as fans (FannedPolygons), or of the
// triangles the reader's split left out where it could not be mended.
void warn_fanned(const FannedPolygons& fanned, const std::string& file, Log& log);

// Warns, naming `file`, of the triangles read once or dropped (RepeatedTriangles), where there
// were any.
void warn_repeated(const RepeatedTriangles& repeated, const std::string& file, Log& log);

// Warns, naming `file`, that its default morph weights were read as 0, where it has any
// (sdf-build: a field of a clip's rest is built from pose-extract's rest.obj).
void warn_default_weights(const DefaultWeights& weights, const std::string& file, Log& log);

// Deterministic Wavefront OBJ text.
std::string to_obj(const TriMesh& mesh, const std::string& comment = {});

// Base name without folder and extension ("poses/front.obj" -> "front").
std::string stem_of(const std::string& path);

}  // namespace spx
