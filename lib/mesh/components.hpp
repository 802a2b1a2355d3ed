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

// A piece as messages name it: "part 2 of 13 (192 triangles around -0.28, 1.099, 0.05143)".
std::string piece_name(const std::string& kind, size_t number, size_t of, size_t triangles, const Eigen::Vector3d& around);

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
