#pragma once
// What is wrong with a mesh, as the sdf-build report names it.
#include <nlohmann/json.hpp>

#include <cmath>
#include <string>
#include <vector>

#include "mesh/mesh.hpp"

namespace spx {

struct MeshDefects {
  size_t vertices = 0, triangles = 0;
  size_t boundary_edges = 0;      // edges with one triangle (holes, open meshes)
  size_t non_manifold_edges = 0;  // edges with three or more triangles
  size_t inconsistent_edges = 0;  // two triangles traverse the edge the same way (flipped faces)
  size_t degenerate_triangles = 0;
  size_t components = 0;          // edge-connected pieces
  double signed_volume = 0;       // divergence theorem; negative when the mesh is inside out
  // Every edge is used as often one way as the other (closed, if not manifold: two boxes welded
  // face to face): the signed volume is then the mesh's, wherever the origin lies.
  bool encloses = true;
  // Closed pieces that face inward and lie in no other piece (the winding number is -1 within
  // them: they enclose nothing, where a cavity's inward shell lies in the body around it), each
  // as "part 2 of 3 (12 triangles around x, y, z)".
  std::vector<std::string> inside_out_parts;
  // Small pieces (at most 1 % of the triangles) apart from the rest, whose removal would shrink
  // the bounding box's diagonal by a fifth or more: a stray triangle far off sets the voxel size
  // and every tolerance given in % of the diagonal. Each named as above, then "stretches the
  // diagonal from D to D'".
  std::vector<std::string> far_parts;

  bool watertight() const { return boundary_edges == 0 && non_manifold_edges == 0 && inconsistent_edges == 0; }
  nlohmann::json to_json() const;
};

MeshDefects find_defects(const TriMesh& mesh);

// The volume enclosed, by the divergence theorem: negative when the mesh is inside out.
double signed_volume(const TriMesh& mesh);
// A signed volume that is rounding alone for a body `extent` across (its box's longest side):
// sides that cancel (faces given both ways) or a flat body.
inline bool negligible_volume(double volume, double extent) {
  return !(std::abs(volume) > 1e-12 * extent * extent * extent);
}

// Triangles with (near) zero area: repeated indices or collinear corners.
bool is_degenerate(const TriMesh& mesh, int triangle, double diagonal);
// The corners' part of that test, for a triangle that is not in a mesh (a piece of one).
bool is_degenerate(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c, double diagonal);

}  // namespace spx
