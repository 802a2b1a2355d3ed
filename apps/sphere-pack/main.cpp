#include "tool/tool.hpp"
#include "pack/sphere_pack.hpp"

int main(int argc, char** argv) {
  spx::Tool tool("sphere-pack", "Greedy sphere packing inside a signed distance field (S_0 of the proxy).");
  std::string input, output, mesh;
  spx::PackOptions opt;
  tool.app.add_option("input", input, "Signed distance field (.vdb from sdf-build)")->required();
  tool.app.add_option("-o,--output", output, "Output .spheres.json")->required();
  tool.app.add_option("--mesh", mesh, "The mesh the field was built from: radii become exact distances to it");
  tool.app.add_option("--min-radius", opt.min_radius, "Stop when the next sphere would be smaller (default 1.5 voxels)");
  tool.app.add_option("--max-radius", opt.max_radius, "Largest radius a sphere may have (default unlimited)");
  tool.app.add_option("--max-spheres", opt.max_spheres, "Stop after this many spheres (default unlimited)")
      ->check(CLI::PositiveNumber);
  std::string tolerance;
  tool.app.add_option("--tolerance", tolerance,
                      "Fewest spheres whose rest max vertex error is at most T (length, or T% of the diagonal); "
                      "needs --mesh");
  bool grid_centers = false;
  tool.app.add_flag("--grid-centers", grid_centers, "Keep centers on voxel centers (the paper's plain greedy)");
  return tool.run(argc, argv, [&] {
    opt.refine_centers = !grid_centers;
    spx::sphere_pack_files(input, mesh, output, opt, spx::parse_tolerance(tolerance, "--tolerance"), tool.log, tool.report);
  });
}
