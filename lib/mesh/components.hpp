#pragma once
// Edge-connected pieces of a mesh: the bodies of a multi-part asset (two animals in one OBJ,
// a car body and its wheels).
#include <string>
#include <vector>

#include "mesh/mesh.hpp"

namespace spx {

struct Components {
  std::vector<int> of_triangle;  // component of each triangle, numbered by first triangle
  size_t count = 0;
};

Components edge_components(const TriMesh& mesh);

// What the checks and messages ask of a piece: its triangles, box, signed volume (by the
// divergence theorem: positive where a closed piece faces outward) and whether every corner lies
// in one plane (a stray triangle, a decal: it encloses no volume at any resolution).
struct PieceShape {
  size_t triangles = 0;
  Eigen::AlignedBox3d box;
  double volume = 0;
  bool flat = false;
};
std::vector<PieceShape> piece_shapes(const TriMesh& mesh, const Components& pieces);

// A piece as messages name it, around its box's centre: "part 2 of 13 (192 triangles around
// -0.28, 1.099, 0.05143)".
std::string piece_name(const std::string& kind, size_t number, size_t of, const PieceShape& piece);

// One use of an edge by a triangle: its ends lo < hi, whether the triangle runs lo to hi.
struct EdgeUse {
  int lo, hi, tri;
  bool forward;
};
// Every non-degenerate edge of every triangle, sorted by (lo, hi, tri): the uses of an edge are
// neighbours. Sorted in parallel (ties differ in `forward` alone, which no caller orders by).
std::vector<EdgeUse> sorted_edge_uses(const TriMesh& mesh);
// The pieces from the sorted uses of `triangles` triangles (what edge_components computes).
Components components_of(size_t triangles, const std::vector<EdgeUse>& sorted);

}  // namespace spx
