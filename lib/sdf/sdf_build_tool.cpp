#include "sdf/sdf_build_tool.hpp"

#include <cstdio>
#include <filesystem>

#include "core/error.hpp"
#include "core/format.hpp"
#include "core/version.hpp"
#include "core/subject.hpp"
#include "io/vdb_io.hpp"

namespace spx {

namespace {

// `mesh` as seen from the folder of `field` (a path that still holds when the two are moved
// together or read from another working folder), or "" where there is none (another drive).
std::string path_from_field(const std::string& mesh, const std::string& field) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path folder = fs::absolute(fs::path(field), ec).parent_path();
  if (ec) return "";
  const fs::path rel = fs::relative(fs::absolute(fs::path(mesh), ec), folder, ec);
  return ec ? "" : rel.generic_string();
}

}  // namespace

void sdf_build_files(const std::string& input, const std::string& output, const SdfOptions& options, Log& log, json& report) {
  LoadedMesh loaded;
  {
    StageTimer t(log, "load");
    loaded = load_mesh(input);
  }
  check_read_rounding(loaded.mesh, voxel_size_for(loaded.mesh, options), input, log);
  warn_fanned(loaded.fanned, input, log);
  warn_repeated(loaded.repeated, input, log);
  warn_default_weights(loaded.default_weights, input, log);
  if (loaded.points_and_lines > 0)
    log.info(input + ": " + std::to_string(loaded.points_and_lines) +
             (loaded.points_and_lines == 1 ? " point or line among its faces is" : " points and lines among its faces are") +
             " left out: they bound no volume");
  const SdfResult sdf = about_file(input, [&] { return build_sdf(loaded.mesh, options, log); });
  const MeshDefects& d = sdf.stats.defects;
  if (!d.watertight())
    log.warn(input + ": not watertight (" + std::to_string(d.boundary_edges) + " boundary, " +
             std::to_string(d.non_manifold_edges) + " non-manifold, " + std::to_string(d.inconsistent_edges) +
             " inconsistently oriented edges); inside is where the winding number exceeds 1/2");
  if (d.degenerate_triangles > 0) log.warn(input + ": " + std::to_string(d.degenerate_triangles) + " degenerate triangles");
  for (const std::string& part : d.far_parts)
    log.warn(input + ": " + part + ", and with it the voxel (--resolution counts along the longest side) and any "
             "tolerance in % of the diagonal; remove it if it is stray");
  // Where every part faces inward the field is empty, and build_sdf says so.
  if (d.inside_out_parts.size() < d.components)
    for (const std::string& part : d.inside_out_parts)
      log.warn(input + ": " + part + " faces inward and lies in no other part: the winding number is -1 within it, "
               "so it encloses no volume and gets no spheres; flip its faces");
  const Eigen::AlignedBox3d bounds = loaded.mesh.bounds();
  char box[200];
  std::snprintf(box, sizeof box, "%.9g %.9g %.9g %.9g %.9g %.9g", bounds.min().x(), bounds.min().y(), bounds.min().z(),
                bounds.max().x(), bounds.max().y(), bounds.max().z());
  {
    StageTimer t(log, "write");
    write_sdf_vdb(output, sdf.field,
                  {{"spx_source_mesh", input},
                   {"spx_source_mesh_from_field", path_from_field(input, output)},
                   {"spx_source_bounds", box},
                   {"spx_open_solid", sdf.stats.bounded_by_holes ? "yes" : "no"},
                   {"spx_sign_method", sdf.stats.sign_method},
                   {"spx_generator", std::string("sdf-build (spx) ") + version_string()}});
  }
  const GridShape& s = sdf.field.shape;
  log.info(output + ": " + counted(loaded.mesh.triangles.size(), "triangle") + " -> " + std::to_string(s.dims.x()) + "x" +
           std::to_string(s.dims.y()) + "x" + std::to_string(s.dims.z()) + " voxels of " + num(s.voxel_size) + ", " +
           std::to_string(sdf.stats.interior_voxels) + " inside");

  report["input"] = input;
  report["output"] = output;
  report["mesh"] = {{"vertices", loaded.mesh.vertices.size()},
                    {"triangles", loaded.mesh.triangles.size()},
                    {"file_vertices", loaded.file_vertex_count()},
                    {"merged_corners", loaded.merged_corners()},
                    {"read_rounding", read_rounding(loaded.mesh)},
                    {"polygons_fanned", loaded.fanned.polygons},
                    {"triangles_left_out", loaded.fanned.left_out()},
                    {"points_and_lines_left_out", loaded.points_and_lines},
                    {"triangles_repeated", loaded.repeated.count},
                    {"inner_sides_dropped", loaded.repeated.inner_sides}};
  report["grid"] = {{"voxel_size", s.voxel_size},
                    {"dims", {s.dims.x(), s.dims.y(), s.dims.z()}},
                    {"origin_index", {s.origin.x(), s.origin.y(), s.origin.z()}},
                    {"band_voxels_exterior", options.band}};
  report["sdf"] = sdf.stats.to_json();
}

}  // namespace spx
