#pragma once
// sphere-pack, the tool: the rest-pose spheres S_0 from a .vdb field, by coverage (default) or
// by the paper's greedy packing, written as a spheres file with its report.
#include "core/json_io.hpp"
#include "core/log.hpp"
#include "pack/select.hpp"

namespace spx {

// sphere-pack IN.vdb -o OUT.spheres.json [--mesh REST] [--tolerance T] [--max-spheres N] [--method M]
void sphere_pack_files(const std::string& input, const std::string& mesh_path, const std::string& output,
                       const SpherePackOptions& options, Log& log, json& report);

}  // namespace spx
