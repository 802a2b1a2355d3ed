#pragma once
// pose-map, the tool: the meshes and the spheres file read, the proxy written with its report.
#include <vector>

#include "core/json_io.hpp"
#include "core/log.hpp"
#include "core/tolerance.hpp"
#include "posemap/posemap.hpp"

namespace spx {

// The tolerances as the user gave them (a length, or a share of the rest's diagonal; unset:
// none): pose_map_files turns them into the options' lengths.
struct PoseMapTolerances {
  Tolerance selection, fill, clip_overshoot;
};

// pose-map's report: the tets, the map, each pose's zero radii and error, the joint selection
// and the gap filling, from what pose_map() returned.
json pose_map_report(const PoseMapResult& result);

// pose-map --rest REST --pose P... --spheres S -o OUT.proxy.json [--skin SKIN]: `skin` (empty:
// none) is the poses' rig, its poses in the order of `poses`; `names` what the proxy calls the
// poses (io/pose_manifest.hpp's pose_names; empty: the files' stems).
void pose_map_files(const std::string& rest, const std::vector<std::string>& poses, const std::string& spheres,
                    const std::string& output, const PoseMapOptions& options, const PoseMapTolerances& tolerances,
                    Log& log, json& report, const std::string& skin = "", const std::vector<std::string>& names = {});

}  // namespace spx
