#include "tool/tool.hpp"
#include "io/pose_manifest.hpp"
#include "metrics/proxy_eval_tool.hpp"

int main(int argc, char** argv) {
  spx::Tool tool("proxy-eval", "Measure a proxy as the paper does: distance from the mesh vertices to the sphere "
                               "union per pose and for blends, coverage of the interior, error colours.");
  tool.when_out_of_memory("try fewer poses, or with --asset every Nth frame (--every)");
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
  // Bounds that catch a mistyped count before it runs for days or fills memory.
  tool.app.add_option("--coverage-samples", opt.eval.coverage_samples, "Grid cells along the longest side for coverage")
      ->capture_default_str()
      ->check(CLI::Range(1, 1024));
  auto* colors =
      tool.app.add_option("--colors", opt.colors, "Per-vertex error colours: .glb (every pose) or .ply (one pose)");
  tool.writes_file("--colors");
  tool.app.add_option("--color-pose", opt.color_pose, "Pose written to a .ply (default 0, the rest)")
      ->check(spx::kNonNegative)
      ->needs(colors);
  tool.app.add_option("--color-scale", opt.color_scale, "Error shown as full red (default: the largest max error)")
      ->check(spx::kPositive)
      ->needs(colors);
  auto& m = opt.motion;
  auto* asset_opt = tool.app.add_option("--asset", m.asset, "Rigged asset the proxy was made from: measure the runtime's "
                                        "skin over a clip of it (every frame asked for and half-way between)");
  tool.app.add_option("--mesh", m.mesh, "With --asset: one mesh (or node) by name, as pose-extract --mesh")->needs(asset_opt);
  tool.app.add_option("--animation", m.animation,
                      "With --asset: the clip, by name or index (default: the clip the manifest's poses came from, "
                      "or the asset's only one)")
      ->needs(asset_opt);
  tool.app.add_option("--every", m.every, "With --asset: every Nth frame of the clip")->capture_default_str()->needs(asset_opt);
  tool.app.add_option("--times", m.times, "With --asset: these times in seconds instead")->needs(asset_opt);
  tool.app.add_option("--between", m.between, "With --asset: also this many times evenly between consecutive ones "
                      "(0: none)")->capture_default_str()->check(CLI::Range(0, 1000))->needs(asset_opt);
  tool.app.add_option("--chart", m.chart, "With --asset: error over the clip as an SVG chart")->needs(asset_opt);
  tool.writes_file("--chart");
  std::string tolerance;
  tool.app.add_option("--tolerance", tolerance, "With --asset: the target, for ratios in the report (T or T% of the "
                      "rest diagonal)")->needs(asset_opt);
  tool.name_option("poses", "--pose");
  tool.name_option("pose", "--color-pose");
  return tool.run(argc, argv, [&] {
    m.tolerance = spx::parse_tolerance(tolerance, "--tolerance");
    m.manifest = manifest;
    if (!manifest.empty() || m.asset.empty()) spx::rest_and_poses(manifest, rest, poses);
    spx::proxy_eval_files(proxy, rest, poses, opt, tool.log, tool.report);
  });
}
