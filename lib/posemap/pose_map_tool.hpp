#pragma once
// pose-map, the tool: the meshes and the spheres file read, the proxy written with its report.
#include <vector>

#include "core/json_io.hpp"
#include "core/log.hpp"
#include "posemap/posemap.hpp"

namespace spx {

// pose-map --rest REST --pose P... --spheres S -o OUT.proxy.json [--skin SKIN]: `skin` (empty:
// none) is the poses' rig, its poses in the order of `poses`.
void pose_map_files(const std::string& rest, const std::vector<std::string>& poses, const std::string& spheres,
                    const std::string& output, const PoseMapOptions& options, Log& log, json& report,
                    const std::string& skin = "");

}  // namespace spx
