#include "tool/tool.hpp"
#include "io/pose_manifest.hpp"
#include "metrics/proxy_eval_tool.hpp"

int main(int argc, char** argv) {
  spx::Tool tool("proxy-eval", "Measure a proxy as the paper does: distance from the mesh vertices to the sphere "
                               "union per pose and for blends, coverage of the interior, error colours.");
  std::string proxy, rest;
  std::vector<std::string> poses;
  spx::EvalToolOptions opt;
  tool.app.add_option("input", proxy, "Proxy from pose-map (.proxy.json)")->required();
  auto* rest_opt = tool.app.add_option("--rest", rest, "Rest mesh M_0");
  auto* pose_opt = tool.app.add_option("--pose", poses, "Example poses M_1..M_e, in the proxy's order");
  std::string manifest;
  tool.app.add_option("--manifest", manifest, "Rest and poses from pose-extract's poses.json (instead of --rest/--pose)")
      ->excludes(rest_opt)->excludes(pose_opt);
  tool.app.add_option("--blends", opt.eval.blends, "Weight vectors to evaluate between examples")->capture_default_str();
  tool.app.add_option("--seed", opt.eval.seed, "Seed of the random blends")->capture_default_str();
  tool.app.add_option("--coverage-samples", opt.eval.coverage_samples, "Grid cells along the longest side for coverage")
      ->capture_default_str();
  tool.app.add_option("--colors", opt.colors, "Per-vertex error colours: .glb (every pose) or .ply (one pose)");
  tool.app.add_option("--color-pose", opt.color_pose, "Pose written to a .ply (0 = rest)")->capture_default_str();
  tool.app.add_option("--color-scale", opt.color_scale, "Error shown as full red (default: the largest max error)");
  tool.name_option("poses", "--pose");
  tool.name_option("pose", "--color-pose");
  return tool.run(argc, argv, [&] {
    spx::rest_and_poses(manifest, rest, poses);
    spx::proxy_eval_files(proxy, rest, poses, opt, tool.log, tool.report);
  });
}
