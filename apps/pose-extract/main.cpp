#include "tool/tool.hpp"
#include "extract/pose_extract_tool.hpp"

int main(int argc, char** argv) {
  spx::Tool tool("pose-extract", "Example poses out of a rigged or morph-target asset: DIR/rest.obj, one OBJ per "
                                 "pose (one welded topology) and DIR/poses.json.");
  tool.when_out_of_memory("try fewer frames: --select, --every or --frames");
  std::string input, dir;
  spx::PoseExtractOptions opt;
  tool.app.add_option("input", input, "Asset: glTF/GLB, FBX, COLLADA (anything assimp reads)")->required();
  tool.app.add_option("-o,--output", dir, "Output folder")->required();
  tool.writes_folder("--output");
  tool.app.add_option("--mesh", opt.mesh, "Only this mesh (or node); default: every mesh, merged into one body");
  auto* morph = tool.app.add_flag("--morph-targets", opt.morph_targets, "One pose per morph target (blend shape)");
  auto* anim = tool.app.add_option("--animation", opt.animation,
                                   "Poses of this clip (name or index) by linear blend skinning and its morph weights");
  morph->excludes(anim);
  std::vector<std::string> frame_words;
  auto* frames = tool.app.add_option("--frames", frame_words,
                                     "Frames of the clip (its key times, from 0): a list, ranges too (0,4,10-20)")
                     ->delimiter(',')->needs(anim);
  auto* times = tool.app.add_option("--times", opt.times, "Times in seconds")->delimiter(',')->needs(anim);
  auto* every = tool.app.add_option("--every", opt.every, "Every Nth frame (default: every frame)")
                    ->check(CLI::Range(1, 1 << 30))->needs(anim);
  frames->excludes(times)->excludes(every);
  times->excludes(every);
  tool.app.add_option("--select", opt.select, "Keep the K frames that best span the clip (farthest-point sampling)")
      ->check(CLI::Range(1, 1 << 30))->needs(anim);
  tool.name_option("morph_targets", "--morph-targets");
  return tool.run(argc, argv, [&] {
    opt.frames = spx::parse_frame_list(frame_words, "--frames");
    spx::pose_extract_files(input, dir, opt, tool.log, tool.report);
  });
}
