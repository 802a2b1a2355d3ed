#include "tool/tool.hpp"
#include "synthetic/sample_gen_tool.hpp"

int main(int argc, char** argv) {
  spx::Tool tool("sample-gen", "Write the project's sample assets: rest mesh and example poses as OBJ, and NAME-morph.glb with the poses as morph targets.");
  std::string name, dir;
  tool.app.add_option("sample", name, "car, barrel or robot")->required();
  tool.app.add_option("-o,--output", dir, "Folder for rest.obj and one OBJ per pose")->required();
  tool.writes_folder("--output");
  return tool.run(argc, argv, [&] { spx::sample_gen_files(name, dir, tool.log, tool.report); });
}
