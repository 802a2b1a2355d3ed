#include "core/error.hpp"
#include "pack/sphere_pack_tool.hpp"
#include "tool/tool.hpp"

int main(int argc, char** argv) {
  spx::Tool tool("sphere-pack", "Choose the rest-pose spheres S_0 inside a signed distance field: by coverage "
                                "(the fewest inscribed spheres within a tolerance, or the least error for a "
                                "budget), or by the paper's greedy packing.");
  tool.when_out_of_memory("try fewer --samples, or a field from a coarser sdf-build --resolution");
  std::string input, output, mesh, tolerance, method = "cover";
  spx::SpherePackOptions opt;
  tool.app.add_option("input", input, "Signed distance field (.vdb from sdf-build)")->required();
  tool.app.add_option("-o,--output", output, "Output .spheres.json")->required();
  tool.writes_file("--output");
  tool.app.add_option("--mesh", mesh, "The mesh the field was built from: exact radii, and the error is measured "
                                      "at its vertices (needed by the cover method and --tolerance; default: the mesh "
                                      "sdf-build recorded in the field, seen from the field's folder or as given to "
                                      "sdf-build, while it is there)");
  tool.app.add_option("--method", method, "cover (default): inscribed spheres chosen by a set cover of the surface; "
                                          "greedy: the paper's packing (deepest first)")
      ->check(CLI::IsMember({"cover", "greedy"}));
  tool.app.add_option("--tolerance", tolerance,
                      "Fewest spheres whose max vertex error is at most T (length, or T% of the diagonal). Default "
                      "with the cover method and no --max-spheres: 2%");
  auto* budget = tool.app.add_option("--max-spheres", opt.pack.max_spheres,
                                     "At most N spheres; the cover method picks the N with the least max error")
                     ->check(spx::kPositive);
  tool.app.add_option("--min-radius", opt.pack.min_radius, "No sphere smaller (greedy default: 1.5 voxels)")
      ->check(spx::kPositive);
  tool.app.add_option("--max-radius", opt.pack.max_radius, "No sphere larger (default unlimited)")->check(spx::kPositive);
  auto* samples = tool.app.add_option("--samples", opt.area_samples, "Cover: surface samples besides every vertex")
                      ->capture_default_str()
                      ->check(CLI::Range(size_t(0), size_t(1000000)));
  auto* seed = tool.app.add_option("--seed", opt.seed, "Cover: seed of the surface samples")->capture_default_str();
  auto* polish = tool.app.add_option("--polish", opt.polish_rounds,
                                     "Cover with --max-spheres: cover again this many times from the refined spheres, "
                                     "keeping a set with no higher max error and a lower max times median (0: faster, "
                                     "the first refinement's)")
                     ->check(CLI::Range(0, 16))
                     ->capture_default_str()
                     ->needs(budget);
  bool every_vertex = false;
  auto* every = tool.app.add_flag("--every-vertex", every_vertex,
                                  "Cover: solve on every vertex from the start, where a mesh far denser than the "
                                  "delta is otherwise covered on vertices an eighth of it apart, then checked at every "
                                  "vertex (the same promise; slower and larger on dense meshes)");
  auto* cache = tool.app.add_option("--cache", opt.cache_dir,
                                    "Cover: keep the candidates no tolerance or budget changes in this folder between "
                                    "runs: a later run on the same field, mesh and samples reads them (the same spheres)");
  tool.writes_folder("--cache");
  spx::add_cache_limit(tool.app, opt.cache_limit, cache);
  bool grid_centers = false;
  tool.app.add_flag("--grid-centers", grid_centers, "Greedy: keep centres on voxel centres (the paper's plain greedy)");
  return tool.run(argc, argv, [&] {
    // An option of the other method would be ignored: said, not dropped.
    for (const CLI::Option* cover_only : {samples, seed, polish, every, cache})
      if (method == "greedy" && cover_only->count() > 0)
        spx::fail_usage(cover_only->get_name(), "is for the cover method (greedy packing takes no surface samples)");
    if (method != "greedy" && grid_centers) spx::fail_usage("--grid-centers", "is for --method greedy");
    opt.method = method == "greedy" ? spx::PackMethod::greedy : spx::PackMethod::cover;
    opt.pack.refine_centers = !grid_centers;
    opt.spaced_vertices = !every_vertex;
    spx::sphere_pack_files(input, mesh, output, opt, spx::parse_tolerance(tolerance, "--tolerance"), tool.log,
                           tool.report);
  });
}
