#pragma once
// Edge-connected pieces of a mesh: the bodies of a multi-part asset (two animals in one OBJ,
// a car body and its wheels).
#include <vector>

#include "mesh/mesh.hpp"

namespace spx {

struct Components {
  std::vector<int> of_triangle;  // component of each triangle, numbered by first triangle
  size_t count = 0;
};

Components edge_components(const TriMesh& mesh);

}  // namespace spx
