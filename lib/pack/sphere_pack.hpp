#pragma once
#include "core/json_io.hpp"
#include "core/log.hpp"
#include "core/tolerance.hpp"
#include "pack/pack.hpp"

namespace spx {


// sphere-pack IN.vdb -o OUT.spheres.json [--mesh REST] [--tolerance T]
void sphere_pack_files(const std::string& input, const std::string& mesh_path, const std::string& output,
                 const PackOptions& options, const Tolerance& tolerance, Log& log, json& report);

}  // namespace spx
