#pragma once
// Which rest vertex each vertex of a pose is, from the triangles alone: for a pose saved in
// another format (a GLB's numbering against an OBJ's) or with its faces listed in another
// order or their corners rotated. Positions are no guide: a pose moves them.
#include <string>
#include <vector>

#include "mesh/mesh.hpp"

namespace spx {

// pose vertex -> rest vertex, such that every pose triangle is a rest triangle (as a set of
// vertices). Both meshes welded. Throws spx::Error naming `path` when no such map exists,
// saying how the triangles differ.
std::vector<int> match_pose_vertices(const TriMesh& rest, const TriMesh& pose, const std::string& path);

}  // namespace spx
