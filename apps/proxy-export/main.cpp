#include "core/error.hpp"
#include "tool/tool.hpp"
#include "export/proxy_export_tool.hpp"

int main(int argc, char** argv) {
  spx::Tool tool("proxy-export", "Write a proxy for the runtime (.spx), as plain JSON (.json), or as sphere "
                                 "meshes to look at (.glb with every pose, .ply with one).");
  std::string input, output;
  spx::ExportOptions opt;
  bool stacked = false;
  tool.app.add_option("input", input, "Proxy from pose-map (.proxy.json)")->required();
  tool.app.add_option("-o,--output", output, "Output: .spx, .json, .glb or .ply")->required();
  tool.app.add_option("--ply-pose", opt.pose, "Pose to write to .ply (0 = rest)")->capture_default_str();
  tool.app.add_flag("--stacked", stacked, "In .glb, keep poses in place instead of side by side");
  tool.app.add_option("--rest", opt.rest, "With the meshes, previews also colour each pose's mesh by its error");
  tool.app.add_option("--pose", opt.poses, "Example poses M_1..M_e in the proxy's order (with --rest)");
  tool.app.add_flag("--physics", opt.physics, "In .glb, the spheres as glTF physics colliders (KHR_physics_rigid_bodies "
                                               "and OMI_physics_body on sphere shapes) instead of meshes");
  tool.app.add_option("--asset", opt.asset, "With --physics: the body's glTF/GLB, written with the colliders "
                                            "(a skinned proxy's spheres on their heaviest joints)");
  tool.name_option("poses", "--pose");
  tool.name_option("pose", "--ply-pose");
  return tool.run(argc, argv, [&] {
    if (!opt.poses.empty() && opt.rest.empty()) spx::fail_usage("--pose", "needs --rest");
    opt.spread = !stacked;
    spx::proxy_export_files(input, output, opt, tool.log, tool.report);
  });
}
