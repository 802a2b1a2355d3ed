#pragma once
// sphere-pack, the tool: the rest-pose spheres S_0 from a .vdb field, by coverage (default) or
// by the paper's greedy packing, written as a spheres file with its report.
#include "core/json_io.hpp"
#include "core/log.hpp"
#include "core/tolerance.hpp"
#include "pack/select.hpp"

namespace spx {

// sphere-pack IN.vdb -o OUT.spheres.json [--mesh REST] [--tolerance T] [--max-spheres N] [--method M]:
// `tolerance` as the user gave it (a length or a share of the mesh's diagonal; unset: none, or
// with the cover method and no --max-spheres the default); options.tolerance is set from it.
void sphere_pack_files(const std::string& input, const std::string& mesh_path, const std::string& output,
                       const SpherePackOptions& options, const Tolerance& tolerance, Log& log, json& report);

}  // namespace spx
