#pragma once
// A mesh split finer: each triangle into four at its edges' midpoints (an edge's two triangles
// share its midpoint), `times` over. The benchmarks and tests make meshes of a scan's density
// from the shared ones with it.
#include <utility>
#include <vector>

#include "mesh/mesh.hpp"

namespace spx {

// `ends`, when given, gets each added vertex's two ends, in order (vertex n of the input's count
// plus k is the midpoint of ends[k]; an end may be a vertex added by an earlier split): what
// carries per-vertex data, such as a skin's weights, onto the split mesh.
TriMesh split_at_midpoints(TriMesh mesh, int times, std::vector<std::pair<int, int>>* ends = nullptr);

}  // namespace spx
