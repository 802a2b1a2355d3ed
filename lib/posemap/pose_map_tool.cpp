#include "posemap/pose_map_tool.hpp"

#include <algorithm>
#include <cstdio>
#include <set>

#include "core/error.hpp"
#include "core/format.hpp"
#include "core/subject.hpp"

namespace spx {
namespace {

// The rig must be the rest mesh's and the poses': weights found for every rest vertex (by its
// position, whatever order the mesh was read in), a pose each.
SkinFile read_matching_skin(const std::string& path, const TriMesh& rest, size_t poses) {
  SkinFile skin = read_skin_file(path);
  // Positions went through OBJ text (9 significant digits): a little of the diagonal, and of the
  // coordinates' size for a body far from the origin.
  double far = 0;
  for (const auto& p : rest.vertices) far = std::max(far, p.cwiseAbs().maxCoeff());
  skin.vertex_weights = weights_for_vertices(skin, rest.vertices, 1e-6 * rest.diagonal() + 1e-8 * far, path);
  skin.vertex_positions = rest.vertices;
  if (skin.poses.size() != poses)
    fail_input(path, "holds the joint matrices of " + std::to_string(skin.poses.size()) + " poses; " +
                         std::to_string(poses) + " poses are given (every pose must come with the rig, or none)");
  return skin;
}

}  // namespace

void pose_map_files(const std::string& rest_path, const std::vector<std::string>& pose_paths,
                    const std::string& spheres_path, const std::string& output, const PoseMapOptions& options,
                    Log& log, json& report, const std::string& skin_path) {
  if (pose_paths.empty()) fail_option("poses", "give at least one example pose");
  LoadedMesh rest;
  std::vector<PoseInput> poses;
  SpheresFile spheres;
  SkinFile skin;
  {
    StageTimer t(log, "load");
    rest = load_mesh(rest_path);
    std::set<std::string> names;
    for (const auto& path : pose_paths) {
      PoseInput pose{stem_of(path), path, load_pose(path, rest)};
      if (!names.insert(pose.name).second) fail_usage(path, "two poses are named '" + pose.name + "'");
      // A pose at another scale is most likely another unit (cm vs m).
      const double ratio = pose.mesh.diagonal() / rest.mesh.diagonal();
      if (ratio > 3 || ratio < 1.0 / 3)
        log.warn(path + ": its size is " + num(ratio) + "x the rest mesh's; is it in another unit?");
      poses.push_back(std::move(pose));
    }
    spheres = read_spheres_file(spheres_path);
    if (!skin_path.empty()) skin = read_matching_skin(skin_path, rest.mesh, poses.size());
  }
  PoseMapResult result = about_file(rest_path, [&] {
    return pose_map(rest.mesh, rest_path, poses, spheres, options, log, skin_path.empty() ? nullptr : &skin);
  });
  write_json_atomic(output, proxy_to_json(result.proxy));

  char line[256];
  std::snprintf(line, sizeof line, "%s: %zu spheres x %zu poses, %zu blend sites", output.c_str(),
                result.proxy.sphere_count(), result.proxy.poses.size(), result.proxy.sites.size());
  log.info(line);
  for (const auto& pose : result.report["poses"]) {
    std::snprintf(line, sizeof line, "  %-12s error median %.4g max %.4g, %zu centers outside",
                  pose["name"].get<std::string>().c_str(), pose["error"]["median"].get<double>(),
                  pose["error"]["max"].get<double>(), pose["outside"].size());
    log.info(line);
  }
  report.update(result.report);
  report["output"] = output;
  if (!skin_path.empty()) report["skin"] = skin_path;
}

}  // namespace spx
