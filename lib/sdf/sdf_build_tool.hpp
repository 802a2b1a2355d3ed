#pragma once
// sdf-build, the tool: a mesh to a .vdb signed distance field, with its defects reported.
#include "core/json_io.hpp"
#include "core/log.hpp"
#include "sdf/sdf.hpp"

namespace spx {

// sdf-build INPUT -o OUT.vdb: load, report defects, build the field, write it.
void sdf_build_files(const std::string& input, const std::string& output, const SdfOptions& options, Log& log, json& report);

}  // namespace spx
