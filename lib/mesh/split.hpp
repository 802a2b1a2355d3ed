#pragma once
// A mesh split finer: each triangle into four at its edges' midpoints (an edge's two triangles
// share its midpoint), `times` over. The benchmarks and tests make meshes of a scan's density
// from the shared ones with it.
#include "mesh/mesh.hpp"

namespace spx {

TriMesh split_at_midpoints(TriMesh mesh, int times);

}  // namespace spx
