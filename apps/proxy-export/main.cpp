#include "core/error.hpp"
#include "tool/tool.hpp"
#include "export/proxy_export_tool.hpp"
#include "io/pose_manifest.hpp"

int main(int argc, char** argv) {
  spx::Tool tool("proxy-export", "Write a proxy for the runtime (.spx), as plain JSON (.json), as sphere meshes to "
                                 "look at (.glb with every pose, .ply with one), as glTF physics colliders (.glb "
                                 "--physics), or as a page that plays it in a browser (.html).");
  std::string input, output;
  spx::ExportOptions opt;
  tool.app.add_option("input", input, "Proxy from pose-map (.proxy.json)")->required();
  tool.app.add_option("-o,--output", output, "Output: .spx, .json, .glb, .ply or .html")->required();
  tool.writes_file("--output");
  tool.app.add_option("--ply-pose", opt.pose, "Pose to write to .ply (default 0, the rest)")->check(spx::kNonNegative);
  tool.app.add_flag("--stacked", opt.stacked, "In .glb, keep poses in place instead of side by side");
  auto* rest_opt = tool.app.add_option("--rest", opt.rest, "Rest mesh M_0: previews colour each pose's mesh by its "
                                       "error, the page shows the body");
  auto* pose_opt = tool.app.add_option("--pose", opt.poses, "Example poses M_1..M_e in the proxy's order (with --rest)");
  std::string manifest;
  tool.app.add_option("--manifest", manifest, "Rest and poses from pose-extract's poses.json (instead of --rest/--pose)")
      ->excludes(rest_opt)->excludes(pose_opt);
  tool.app.add_flag("--physics", opt.physics, "In .glb, the spheres as glTF physics colliders (KHR_physics_rigid_bodies "
                                               "and OMI_physics_body on sphere shapes) instead of meshes");
  tool.app.add_option("--asset", opt.asset, "With --physics: the body's glTF/GLB, written with the colliders (a "
                                            "skinned proxy's spheres on their heaviest joints); with .html: the "
                                            "skinned body and its clips, played");
  tool.app.add_option("--mesh", opt.mesh, "With .html and --asset: one mesh (or node) of it by name, as pose-extract "
                                          "--mesh took it");
  tool.app.add_option("--up", opt.up, "With .html: the up axis, y or z (default: y with --asset or --manifest, "
                                      "else z)");
  tool.name_option("poses", "--pose");
  tool.name_option("pose", "--ply-pose");
  return tool.run(argc, argv, [&] {
    if (!opt.poses.empty() && opt.rest.empty()) spx::fail_usage("--pose", "needs --rest");
    if (!manifest.empty()) spx::rest_and_poses(manifest, opt.rest, opt.poses);
    opt.manifest = manifest;
    spx::proxy_export_files(input, output, opt, tool.log, tool.report);
  });
}
