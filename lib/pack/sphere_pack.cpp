#include "pack/sphere_pack.hpp"

#include <cstdio>
#include <cmath>
#include <memory>
#include <sstream>

#include "core/error.hpp"
#include "core/format.hpp"
#include "core/subject.hpp"
#include "io/spheres_file.hpp"
#include "io/vdb_io.hpp"

namespace spx {

namespace {

// --mesh must be the mesh the field was built from: with a pose or another model, centers come
// from one shape and radii from another. Its bounds must match those sdf-build recorded, and
// its vertices must lie on the field's zero level (distance is 1-Lipschitz: a voxel's |value|
// less its offset to the vertex bounds the vertex's own distance to the field's surface).
void check_mesh_matches_field(const TriMesh& mesh, const std::string& mesh_path, const LoadedSdf& sdf,
                              const std::string& sdf_path) {
  const GridShape& g = sdf.field.shape;
  const double h = g.voxel_size;
  const auto source = sdf.metadata.find("spx_source_mesh");
  const std::string built_from = source == sdf.metadata.end() ? "" : " (built from " + source->second + ")";
  auto mismatch = [&](const std::string& how) {
    fail_input(mesh_path, "is not the mesh " + sdf_path + built_from + " was built from: " + how);
  };
  size_t off_surface = 0;
  for (const Eigen::Vector3d& p : mesh.vertices) {
    const Eigen::Vector3i v = ((p / h).array().round().cast<int>() - g.origin.array()).matrix();
    if ((v.array() < 0).any() || (v.array() >= g.dims.array()).any()) {
      ++off_surface;
      continue;
    }
    const double value = std::abs(sdf.field.values[g.index(v.x(), v.y(), v.z())]);
    off_surface += value - (g.world(v.x(), v.y(), v.z()) - p).norm() > 2 * h;
  }
  if (off_surface > mesh.vertices.size() / 100)
    mismatch(std::to_string(off_surface) + " of its " + std::to_string(mesh.vertices.size()) +
             " vertices lie more than 2 voxels off the field's surface (a pose, or another model?)");
  const auto recorded = sdf.metadata.find("spx_source_bounds");
  if (recorded != sdf.metadata.end()) {
    std::istringstream in(recorded->second);
    Eigen::Vector3d lo, hi;
    if (in >> lo.x() >> lo.y() >> lo.z() >> hi.x() >> hi.y() >> hi.z()) {
      const Eigen::AlignedBox3d b = mesh.bounds();
      const double off = std::max((b.min() - lo).cwiseAbs().maxCoeff(), (b.max() - hi).cwiseAbs().maxCoeff());
      if (off > 0.25 * h)
        mismatch("its bounding box differs from the field's mesh by " + num(off) + " (" + num(off / h) + " voxels)");
    }
  }
}

}  // namespace

void sphere_pack_files(const std::string& input, const std::string& mesh_path, const std::string& output,
                 const PackOptions& user_options, const Tolerance& tolerance, Log& log, json& report) {
  if (tolerance.set() && mesh_path.empty())
    fail_option("tolerance", "needs the mesh (the error is measured at its vertices)");
  PackOptions options = user_options;
  LoadedSdf sdf;
  {
    StageTimer t(log, "load");
    sdf = read_sdf_vdb(input);
  }
  auto open = sdf.metadata.find("spx_open_solid");
  options.field_bounds_radius = open != sdf.metadata.end() && open->second == "yes";
  if (options.field_bounds_radius) log.detail("open mesh: radii are also bounded by the field across its holes");
  std::unique_ptr<MeshQuery> mesh;
  if (!mesh_path.empty()) {
    StageTimer t(log, "mesh");
    const LoadedMesh loaded = load_mesh(mesh_path);
    check_mesh_matches_field(loaded.mesh, mesh_path, sdf, input);
    mesh = about_file(mesh_path, [&] { return std::make_unique<MeshQuery>(loaded.mesh); });
    if (tolerance.set()) {
      // Pack the whole greedy sequence down to a fine floor, then keep the shortest prefix.
      options.max_spheres = 0;
      if (!(user_options.min_radius > 0)) options.min_radius = sdf.field.shape.voxel_size;
    }
  } else {
    log.detail("no mesh: radii come from the field (voxel accuracy)");
  }
  PackResult packed;
  {
    StageTimer t(log, "pack");
    packed = about_file(input, [&] { return pack_spheres(sdf.field, options, mesh.get(), log); });
  }
  if (packed.spheres.empty())
    fail_input(input, "no sphere fits: the largest interior distance is below the min radius " +
                          num(packed.stats.min_radius));
  double tolerance_target = 0;
  if (tolerance.set()) {
    StageTimer t(log, "tolerance");
    const double diagonal = mesh->mesh().diagonal();
    const double target = tolerance.length(diagonal);
    if (target >= 0.1 * diagonal)
      log.warn("tolerance " + num(tolerance.value) + (tolerance.percent ? "%" : "") + " is " +
               num(100 * target / diagonal) + "% of the mesh's bounding-box diagonal (" + num(diagonal) + ")" +
               (tolerance.percent ? "" : "; did you mean " + num(tolerance.value) + "%?"));
    const ToleranceResult tr = fewest_spheres_within(mesh->mesh(), packed.spheres, target);
    size_t keep = tr.count;
    std::string limit = tr.met ? "met the tolerance" : "the packing sequence ended before the tolerance was met";
    if (user_options.max_spheres > 0 && user_options.max_spheres < keep) {
      keep = user_options.max_spheres;
      limit = "max_spheres (tighter than the tolerance)";
    }
    packed.spheres.resize(keep);
    packed.stats.stop_reason = limit;  // the prefix, not the packing that made the sequence, decides
    tolerance_target = target;
    const double reached = tr.max_error_by_count.empty() ? 0 : tr.max_error_by_count[keep - 1];
    if (!tr.met) {
      char msg[400];
      std::snprintf(msg, sizeof msg,
                    "tolerance %.4g not met: max error %.4g with all %zu spheres down to radius %.4g at voxel size "
                    "%.4g; use a finer resolution or a smaller min radius",
                    target, reached, keep, options.min_radius, sdf.field.shape.voxel_size);
      log.warn(msg);
    }
    report["tolerance"] = {{"target", target},   {"given", tolerance.value},
                           {"percent", tolerance.percent}, {"met", tr.met},
                           {"max_error", reached},         {"spheres", keep},
                           {"limited_by", limit},          {"sequence_length", tr.max_error_by_count.size()}};
  }
  packed.stats.set_radius_range(packed.spheres);  // after the tolerance prefix
  SpheresFile file;
  file.spheres = packed.spheres;
  file.voxel_size = sdf.field.shape.voxel_size;
  file.min_radius = packed.stats.min_radius;
  file.max_radius = packed.stats.max_radius;
  file.radius_source = packed.stats.radius_source;
  file.tolerance = tolerance_target;
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
