#pragma once
// Whether a spheres file belongs with the rest mesh pose-map is given, and the poses with it: the
// checks that name the file and the likely mix-up (another mesh's spheres, another unit, a pose
// given as the rest, a mirrored pose).
#include <string>

#include "core/error.hpp"
#include "io/spheres_file.hpp"
#include "mesh/mesh_query.hpp"
#include "sdf/sdf.hpp"

namespace spx {

// Every rest sphere must lie inside the rest mesh (within a ten-thousandth of its diagonal).
void check_spheres_fit(const MeshQuery& rest, const SpheresFile& spheres, const std::string& rest_source);

// A closed body's pose encloses a volume as its rest does: one that is inside out (mirrored, or
// its faces flipped) would leave every sphere outside it. Exit 2 naming `pose_source`.
void check_pose_faces_outward(const TriMesh& pose, const std::string& pose_source);

// A field at the spheres file's voxel over `mesh_source` was refused as too large for memory
// (`e`): the same failure, saying whose voxel it was and what to do.
[[noreturn]] void fail_field_too_fine(const GridTooLarge& e, const SpheresFile& spheres, const std::string& mesh_source);

}  // namespace spx
