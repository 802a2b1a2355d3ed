#include "tool/tool.hpp"
#include "io/pose_manifest.hpp"
#include "io/spx_writer.hpp"
#include "posemap/pose_map_tool.hpp"

int main(int argc, char** argv) {
  spx::Tool tool("pose-map", "Move and resize the rest spheres into every example pose (S_1..S_e) and give "
                             "each sphere its blend site.");
  tool.when_out_of_memory("try fewer poses, fewer --samples, or a rest field from a coarser sdf-build --resolution");
  std::string rest, spheres, output;
  std::vector<std::string> poses;
  spx::PoseMapOptions opt;
  auto* rest_opt = tool.app.add_option("--rest", rest, "Rest mesh M_0");
  auto* pose_opt = tool.app.add_option("--pose", poses, "Example pose M_i (same topology as the rest mesh); repeat");
  std::string manifest;
  std::string skin;
  auto* skin_opt = tool.app.add_option("--skin", skin, "The poses' rig (pose-extract's skin.json): the spheres follow "
                                                       "the skin, one radius each in every frame");
  tool.app.add_option("--manifest", manifest, "Rest and poses (and a clip's skin) from pose-extract's poses.json "
                                              "(instead of --rest/--pose/--skin)")
      ->excludes(rest_opt)->excludes(pose_opt)->excludes(skin_opt);
  tool.app.add_option("--spheres", spheres, "Rest spheres from sphere-pack")->required();
  tool.app.add_option("-o,--output", output, "Output .proxy.json")->required();
  tool.writes_file("--output");
  tool.app.add_option("--tet-size", opt.tets.size, "Tet edge length (default: bounding-box diagonal / 30)")
      ->check(spx::kPositive);
  auto* tets = tool.app.add_option("--tets", opt.tet_file,
                                   "Use this tet mesh of the rest shape (MEDIT .mesh) instead of meshing");
  auto* cache = tool.app.add_option("--cache", opt.cache_dir,
                      "Keep what no tolerance or budget changes (the rest's tets; each pose's field's depths, "
                      "medial voxels and the candidates grown at them; a skinned body's carries and radii held over "
                      "the clip) in this folder between runs: a later run on the same rest, poses, --tet-size and "
                      "tools reads them instead of making them (the same proxy)")
      ->excludes(tets);
  tool.writes_folder("--cache");
  spx::add_cache_limit(tool.app, opt.cache_limit, cache);
  tool.app.add_option("--max-radius", opt.max_radius, "Largest radius in the poses (default: the spheres file's)")
      ->check(spx::kPositive);
  auto* fill = tool.app.add_flag("--fill-gaps", opt.fill_gaps,
                                 "Pack what each pose's mapped spheres leave uncovered and map the new spheres back "
                                 "to rest");
  std::string fill_tolerance;
  tool.app.add_option("--fill-tolerance", fill_tolerance,
                      "Fill each pose until its max vertex error is at most this (default: the spheres file's "
                      "--tolerance, else the rest pose's max error)")
      ->needs(fill);
  tool.app.add_option("--fill-min-radius", opt.fill_min_radius, "Smallest gap-filling sphere (default: 3/4 voxel)")
      ->check(spx::kPositive)
      ->needs(fill);
  std::string tolerance;
  auto* tolerance_opt =
      tool.app.add_option("--tolerance", tolerance,
                          "Select one sphere set from the spheres file's candidates so that the rest and every pose "
                          "are within T (length, or T% of the rest diagonal). Default: the spheres file's tolerance");
  auto* budget = tool.app.add_option("--max-spheres", opt.max_spheres,
                                     "Select at most N spheres with the least max error over the rest and every pose")
                     ->check(spx::kPositive);
  auto* hold = tool.app.add_flag("--hold-over-clip", opt.hold_over_clip,
                                 "Rigged: each sphere's one radius also holds at every frame of the clip and half-way "
                                 "between (the skin's clip), not only at the poses");
  auto* blends = tool.app.add_flag("--hold-over-blends", opt.hold_over_blends,
                                   "Blended examples: each sphere's radii scaled down where it pokes out at the blends "
                                   "a host plays between them (every two examples half and half; morph targets from "
                                   "pose-extract --morph-targets also two or more at 1 at once), not only at the "
                                   "examples")
                    ->excludes(hold);
  std::string clip_overshoot;
  tool.app.add_option("--clip-overshoot", clip_overshoot,
                      "With --hold-over-clip: how far a sphere may poke out at the clip's times between the poses "
                      "(length, or T% of the rest diagonal; default 0.25%)")
      ->needs(hold);
  auto* given = tool.app.add_flag("--map-given", opt.map_given,
                                  "Map the spheres file's spheres as they are (the paper's S_1..S_e) instead of "
                                  "selecting");
  // Not given: the spheres file's, as sphere-pack drew its samples.
  size_t area_samples = 0;
  uint64_t seed_value = 0;
  bool every_vertex = false;
  auto* samples = tool.app.add_option("--samples", area_samples,
                                      "Selection: surface samples per pose besides every vertex (default: as "
                                      "sphere-pack's --samples, 4000 unless it was given one)")
                      ->check(CLI::Range(size_t(0), size_t(1000000)));
  auto* seed = tool.app.add_option("--seed", seed_value, "Selection: seed of the surface samples (default: as "
                                                         "sphere-pack's --seed, 1 unless it was given one)");
  auto* every = tool.app.add_flag("--every-vertex", every_vertex,
                                  "Selection with a tolerance: solve on every vertex of each pose from the start, where "
                                  "a pose far denser than the tolerance is otherwise covered on vertices an eighth of "
                                  "it apart, then checked at every vertex (the same promise; slower and larger; "
                                  "default: as sphere-pack was given --every-vertex)");
  auto* min_radius = tool.app.add_option("--min-radius", opt.min_radius,
                                         "Selection: no sphere smaller than this at rest (a rigged body's: its one "
                                         "radius) (default: the spheres file's --min-radius, where sphere-pack was "
                                         "given one)")
                         ->check(spx::kPositive);
  auto* polish = tool.app.add_option("--polish", opt.polish_rounds,
                                     "Selection with --max-spheres: cover again this many times from the refined "
                                     "spheres, keeping a set with no higher max error over the poses and a lower max "
                                     "times median (default 1, and 0 for a rigged body; 0: faster, the first "
                                     "refinement's)")
                     ->check(CLI::Range(0, 16));
  tool.app.add_option("--fill-max", opt.fill_max_per_pose, "At most this many gap-filling spheres per pose")
      ->check(spx::kPositive)
      ->needs(fill);
  // --map-given maps the file's spheres as they are: no selection for these to steer.
  for (CLI::Option* selection : {tolerance_opt, budget, samples, seed, polish, every, min_radius})
    given->excludes(selection);
  tool.name_option("poses", "--pose");
  return tool.run(argc, argv, [&] {
    const spx::PoseMapTolerances tolerances{spx::parse_tolerance(tolerance, "--tolerance"),
                                            spx::parse_tolerance(fill_tolerance, "--fill-tolerance"),
                                            spx::parse_tolerance(clip_overshoot, "--clip-overshoot")};
    spx::rest_and_poses(manifest, rest, poses, &skin);
    if (blends->count() && !manifest.empty())
      opt.morph_targets = spx::poses_are_morph_targets(spx::read_pose_manifest(manifest));
    if (samples->count()) opt.area_samples = area_samples;
    if (seed->count()) opt.seed = seed_value;
    if (every->count()) opt.every_vertex = every_vertex;
    // The proxy must reach a host: a clip too long for a .spx is refused before minutes of work.
    spx::check_spx_pose_count(poses.size() + 1, manifest.empty() ? "--pose" : manifest);
    spx::pose_map_files(rest, poses, spheres, output, opt, tolerances, tool.log, tool.report, skin,
                        spx::pose_names(manifest, poses));
  });
}
