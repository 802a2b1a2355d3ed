#pragma once
// Normals of a triangle mesh: the faces' and the vertices' angle-weighted ones (Baerentzen and
// Aanaes 2005), which do not depend on how a vertex's ring is triangulated.
#include <Eigen/Core>
#include <vector>

#include "mesh/mesh.hpp"

namespace spx {

// Each triangle's unit normal by its winding (zero for a degenerate one).
std::vector<Eigen::Vector3d> face_normals(const TriMesh& mesh);

// Each vertex's angle-weighted normal: over its corners, the corner's angle times its face's
// unit normal (`faces`, from face_normals), summed in triangle order so that the result does not
// depend on threads. Not normalised; zero where every face at the vertex is degenerate.
std::vector<Eigen::Vector3d> angle_weighted_normals(const TriMesh& mesh, const std::vector<Eigen::Vector3d>& faces);

}  // namespace spx
