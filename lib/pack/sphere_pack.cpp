#include "pack/sphere_pack.hpp"

#include <cstdio>
#include <memory>

#include "core/error.hpp"
#include "core/subject.hpp"
#include "pack/spheres_file.hpp"
#include "sdf/vdb_io.hpp"

namespace spx {

void sphere_pack(const std::string& input, const std::string& mesh_path, const std::string& output,
                 const PackOptions& options, Log& log, json& report) {
  LoadedSdf sdf;
  {
    StageTimer t(log, "load");
    sdf = read_sdf_vdb(input);
  }
  std::unique_ptr<MeshQuery> mesh;
  if (!mesh_path.empty()) {
    StageTimer t(log, "mesh");
    const LoadedMesh loaded = load_mesh(mesh_path);
    mesh = about_file(mesh_path, [&] { return std::make_unique<MeshQuery>(loaded.mesh); });
  } else {
    log.detail("no --mesh: radii come from the field (voxel accuracy)");
  }
  PackResult packed;
  {
    StageTimer t(log, "pack");
    packed = about_file(input, [&] { return pack_spheres(sdf.field, options, mesh.get(), log); });
  }
  if (packed.spheres.empty())
    fail_input(input, "no sphere fits: the largest interior distance is below the min radius " +
                          std::to_string(packed.stats.min_radius));
  SpheresFile file;
  file.spheres = packed.spheres;
  file.voxel_size = sdf.field.shape.voxel_size;
  file.min_radius = packed.stats.min_radius;
  file.max_radius = packed.stats.max_radius;
  file.radius_source = packed.stats.radius_source;
  file.sdf = input;
  file.mesh = mesh_path;
  write_json_atomic(output, spheres_to_json(file));

  char line[256];
  std::snprintf(line, sizeof line, "%s: %zu spheres, radii %.4g..%.4g (%s)", output.c_str(), packed.spheres.size(),
                packed.stats.smallest, packed.stats.largest, packed.stats.stop_reason.c_str());
  log.info(line);
  report["input"] = input;
  report["output"] = output;
  report["sphere_count"] = packed.spheres.size();
  report["pack"] = packed.stats.to_json();
}

}  // namespace spx
