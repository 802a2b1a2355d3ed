#include "tool/tool.hpp"
#include "sdf/sdf_build_tool.hpp"

int main(int argc, char** argv) {
  spx::Tool tool("sdf-build", "Signed distance field of a mesh with distances through the whole interior "
                              "(negative inside), written as an OpenVDB .vdb file.");
  tool.when_out_of_memory("try a coarser --resolution");
  std::string input, output;
  spx::SdfOptions opt;
  tool.app.add_option("input", input, "Mesh: OBJ, PLY, STL, OFF, glTF/GLB, FBX")->required();
  tool.app.add_option("-o,--output", output, "Output .vdb file")->required();
  tool.writes_file("--output");
  auto* res = tool.app.add_option("--resolution", opt.resolution, "Voxels along the longest side of the bounding box")
                  ->capture_default_str();
  auto* vs = tool.app.add_option("--voxel-size", opt.voxel_size, "Voxel size in mesh units (instead of --resolution)")
                 ->check(spx::kPositive);
  res->excludes(vs);
  tool.app.add_option("--band", opt.band, "Exterior narrow band in voxels")->capture_default_str();
  tool.app.add_option("--memory-limit", opt.memory_limit_gib, "Refuse grids needing more memory than this (GiB)")
      ->capture_default_str()
      ->check(spx::kPositive);
  return tool.run(argc, argv, [&] { spx::sdf_build_files(input, output, opt, tool.log, tool.report); });
}
