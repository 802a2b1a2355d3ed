#include <filesystem>

#include "core/atomic_file.hpp"
#include "core/error.hpp"
#include "core/tool.hpp"
#include "samples/samples.hpp"

int main(int argc, char** argv) {
  spx::Tool tool("sample-gen", "Write the project's sample assets (rest mesh and example poses as OBJ).");
  std::string name, dir;
  tool.app.add_option("sample", name, "car or barrel")->required();
  tool.app.add_option("-o,--output", dir, "Folder for rest.obj and one OBJ per pose")->required();
  return tool.run(argc, argv, [&] {
    const spx::SampleAsset asset = spx::make_sample(name);
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (ec) spx::fail_write(dir, "cannot create folder: " + ec.message());
    const std::string tag = "spx sample " + name;
    spx::write_file_atomic(dir + "/rest.obj", spx::to_obj(asset.rest, tag + " rest pose"));
    for (size_t i = 0; i < asset.pose_names.size(); ++i)
      spx::write_file_atomic(dir + "/" + asset.pose_names[i] + ".obj",
                             spx::to_obj(asset.pose(i), tag + " pose " + asset.pose_names[i]));
    tool.log.info(dir + ": rest + " + std::to_string(asset.pose_names.size()) + " poses, " +
                  std::to_string(asset.rest.triangles.size()) + " triangles");
    tool.report["triangles"] = asset.rest.triangles.size();
    tool.report["poses"] = asset.pose_names;
  });
}
