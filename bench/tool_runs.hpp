#pragma once
// The toolchain timed as a user runs it: each tool a whole process (posix_spawn), its wall time
// and its own peak memory (wait4's rusage, which starts from the spawning process's own: spawn
// before growing), side by side in one run.
#include <cstdarg>
#include <cstdio>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/log.hpp"

namespace spx::bench {

// A result line, printf-formatted, shown unless -q (the log's info).
inline void say(const Log& log, const char* format, ...) __attribute__((format(printf, 2, 3)));
inline void say(const Log& log, const char* format, ...) {
  char line[1024];
  va_list args;
  va_start(args, format);
  std::vsnprintf(line, sizeof line, format, args);
  va_end(args);
  log.info(line);
}

// The middle value (the upper of the two middle ones for an even count; 0 for none).
double median(std::vector<double> values);

struct ToolRun {
  double seconds = 0;
  double peak_gib = 0;
};

// Runs `tools_dir`/argv[0] with the rest of argv, output discarded; throws naming the command
// if it does not exit 0.
ToolRun run_tool(const std::string& tools_dir, const std::vector<std::string>& argv);

// The folder of this program's sibling tools (build/<preset>/apps).
std::string tools_dir_beside_this_program();

// The chain on a rest mesh and its poses (files), three times per repeat in turn: the paper's
// route (greedy packing, pose-map mapping those spheres as given), the default route (coverage
// selection, joint selection) and the default route with both tools' --cache (written by one
// untimed run first; throws unless it writes the fresh route's spheres and proxy), each stage a
// process. Medians per stage and of the totals, the ratios, each route's peak memory and sphere
// count, and the rest's triangles.
nlohmann::json route_case(const std::string& tools, const std::string& name, const std::string& rest,
                          const std::vector<std::string>& poses, const std::string& work, int repeats, const Log& log);

// pose-map at the defaults on `frames` frames of one clip (pose-extract with `extract` plus
// --select N or the times it gives), for each count: median time and peak memory of `repeats`
// runs (1 past 64 frames), spheres, and the median of its per-repeat ratios to the first count
// (the counts take turns within each repeat), and the rest's triangles. The rest's field and
// spheres are built once. `with_cache`: each run is followed by one with --cache (written by one
// untimed run per count first; throws unless its proxy is the fresh one's), timed the same way.
struct ClipSweep {
  std::string name, asset;
  std::vector<std::string> extract;                                   // pose-extract options besides -o
  std::function<std::vector<std::string>(size_t n)> frames_option;  // the options that take n frames
};
nlohmann::json frame_sweep(const std::string& tools, const ClipSweep& clip, const std::vector<size_t>& frames,
                           const std::string& work, int repeats, bool with_cache, const Log& log);

// sphere-pack on `rest` split at its midpoints `split` times (a scan's density): spaced (the
// default) against --every-vertex, at the default tolerance and, where `budget` > 0, at that many
// spheres (under a million triangles); the two in turn `repeats` times (once past a million
// triangles, where every vertex takes minutes and gigabytes). Per mode: median time, most memory, spheres, max and median
// vertex error (the reports'), the samples the cover was solved on, and every vertex's time over
// the spaced one's.
nlohmann::json dense_case(const std::string& tools, const std::string& name, const std::string& rest, int split,
                          size_t budget, const std::string& work, int repeats, const Log& log);

// pose-map on `rest` and its `poses` split at their midpoints `split` times, from sphere-pack's
// spheres at the default tolerance: spaced (the default) against --every-vertex, in turn
// `repeats` times (once past half a million triangles). Per way: median time, most memory,
// spheres, the worst pose's max and the poses' mean median vertex error (the report's), the
// samples after joining and the rounds; and every vertex's time over the spaced one's.
nlohmann::json dense_poses_case(const std::string& tools, const std::string& name, const std::string& rest,
                                const std::vector<std::string>& poses, int split, const std::string& work, int repeats,
                                const Log& log);

// The same for a rigged asset's frames, pose-map following the skin: pose-extract `extract`
// (its clip and frames) from `asset`, then the rest split `split` times, each midpoint weighed by
// its ends half and half, and every frame skinned afresh (split_skinned).
nlohmann::json dense_skinned_case(const std::string& tools, const std::string& name, const std::string& asset,
                                  const std::vector<std::string>& extract, int split, const std::string& work,
                                  int repeats, const Log& log);

// A body for the routes and the batch: its rest mesh and poses (files).
struct RouteBody {
  std::string name, rest;
  std::vector<std::string> poses;
};

// A farm's night: the default route (sdf-build, sphere-pack, pose-map, each a process) on every
// chain, three ways in turn, `repeats` times: one chain at a time on every core; two at a time
// with --threads 1 each; two at a time on every core each (make -j2 without --threads). Per way:
// the batch's median time, the median of its per-repeat ratios to the first way's, and the most
// memory one process took. Throws unless every way writes the first way's proxies byte for byte.
nlohmann::json batch_case(const std::string& tools, const std::vector<RouteBody>& chains, const std::string& work,
                          int repeats, const Log& log);

}  // namespace spx::bench
