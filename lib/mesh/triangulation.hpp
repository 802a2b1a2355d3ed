#pragma once
// How a file's polygons were split into triangles, kept so that the poses of a polygon mesh are
// split as their rest was. assimp splits each polygon by its shape (a quad from its concave
// corner, a larger polygon by ear clipping), so a pose whose quad turned concave was split along
// its other diagonal, and its triangles no longer matched the rest's: a crumpled quad mesh, the
// same faces as its rest, was refused as "another topology".
#include <Eigen/Core>

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

struct aiScene;
namespace Assimp {
class Importer;
}

namespace spx {

// A scene's faces as read (after its placement, before triangulation): each mesh's faces, their
// corners in order (face f's are corners[start[f]] to corners[start[f + 1]] - 1).
struct FaceLists {
  struct Mesh {
    std::vector<uint32_t> start{0};
    std::vector<unsigned> corners;
    bool operator==(const Mesh& o) const { return start == o.start && corners == o.corners; }
  };
  std::vector<Mesh> meshes;
};
FaceLists face_lists(const aiScene& scene);
// A face of more than 3 corners in some mesh of `scene`.
bool has_polygons(const aiScene& scene);
// The faces of 1 or 2 corners (an OBJ's `p` and `l`, a glTF's points and lines): no surface, so
// the mesh reader leaves them out, and the tools count them.
size_t points_and_lines(const aiScene& scene);

struct Triangulation {
  FaceLists faces;  // the faces it split
  // Each face of more than 3 corners, in order over the meshes: its triangles, as corners of the
  // face (0 to n-1).
  std::vector<std::vector<std::array<uint16_t, 3>>> polygons;
  bool empty() const { return polygons.empty(); }
};

// What assimp's aiProcess_Triangulate made of `before` (`after`: the same scene once it ran);
// empty where there was no polygon, or where a face's triangles cannot be told from the next
// face's (no pose then follows it: each is split by its own shape, as before).
Triangulation triangulation_of(const FaceLists& before, const aiScene& after);

// The polygons whose split assimp left unfinished: one that crosses itself as seen along its
// normal (a star, a twisted n-gon) can leave its ear clipping without an ear, and assimp then
// logs it and stops, the rest of the polygon dropped and the mesh opened there.
struct FannedPolygons {
  size_t polygons = 0;      // split as fans from their first corner instead
  size_t dropped = 0;       // the triangles assimp's split had left out of them
  size_t first_corners = 0; // the first one's corners
  Eigen::Vector3d first_at = Eigen::Vector3d::Zero();  // and its first corner
  // Triangles left out and not mended (where assimp's split could not be followed polygon by
  // polygon, so none was fanned): the mesh is open there.
  size_t left_out() const { return polygons > 0 ? 0 : dropped; }
};

// aiProcess_Triangulate on `importer`'s scene, whose faces are `faces` (`path`, `what`: for its
// errors), each polygon it left unfinished split instead as a fan from its first corner: a fan
// uses each edge of its polygon once, as the polygon did, so the mesh stays as closed as the
// file's. Each polygon that repeats an earlier one's corner positions, from another first corner
// or in the other turn (faces doubled, a part given both ways), is split as that one was, so that
// its triangles repeat that one's (read once after). Returns the split, as triangulation_of;
// `fanned` says what was mended.
Triangulation triangulate(Assimp::Importer& importer, const FaceLists& faces, const std::string& path,
                          const std::string& what, FannedPolygons& fanned);

// Splits the polygons of `scene` (whose faces are `faces`) as `rest` split its own, where the two
// are the same faces, corner for corner: true, and `scene` holds no polygon after; else false,
// `scene` as it was.
bool split_as(aiScene& scene, const FaceLists& faces, const Triangulation& rest);

}  // namespace spx
