#include "posemap/spheres_fit.hpp"

#include "core/format.hpp"
#include "mesh/defects.hpp"

namespace spx {

void check_spheres_fit(const MeshQuery& rest, const SpheresFile& spheres, const std::string& rest_source) {
  const double slack = 1e-4 * rest.surface().diagonal();
  size_t misfits = 0;
  for (const auto& s : spheres.spheres)
    if (!rest.inside(s.center) || rest.distance(s.center) < s.radius - slack) ++misfits;
  if (misfits > 0)
    fail_input(rest_source, std::to_string(misfits) + " of " + std::to_string(spheres.spheres.size()) +
                                " spheres do not fit inside this rest mesh (packed from another mesh, or are the rest "
                                "mesh and a pose swapped?)" +
                                (spheres.mesh.empty() ? "" : "; the spheres file was packed from " + spheres.mesh));
}

void check_pose_faces_outward(const TriMesh& pose, const std::string& pose_source) {
  const double volume = signed_volume(pose);
  if (volume < 0)
    fail_input(pose_source, "is inside out (signed volume " + num(volume) +
                                "): its triangles face inward, as in a mirrored pose, so no sphere would be inside "
                                "it; flip its faces");
}

void fail_field_too_fine(const GridTooLarge& e, const SpheresFile& spheres, const std::string& mesh_source) {
  // The grid's size, without sdf-build's own advice (a coarser --resolution there means another spheres file here).
  fail_unsupported(mesh_source, "the spheres file's voxel (" + num(spheres.voxel_size) +
                                    (spheres.mesh.empty() ? "" : ", packed from " + spheres.mesh) +
                                    ") is too fine for this mesh: " + e.grid() +
                                    "; is the spheres file another mesh's, or in another unit? Else pack it from a "
                                    "coarser field (sdf-build --resolution, then sphere-pack)");
}

}  // namespace spx
