#pragma once
// proxy-export, the tool: a proxy to the runtime .spx, a plain JSON dump, or GLB/PLY previews
// (coloured by error when the meshes are given).
#include "core/json_io.hpp"
#include "core/log.hpp"

#include <string>
#include <vector>

namespace spx {

struct ExportOptions {
  int pose = 0;        // for .ply
  bool spread = true;  // .glb: lay poses side by side
  // With the meshes, .glb/.ply previews also show each pose's mesh coloured by its error.
  std::string rest;
  std::vector<std::string> poses;
};

// proxy-export IN.proxy.json -o OUT.spx | OUT.json | OUT.glb | OUT.ply
void proxy_export_files(const std::string& input, const std::string& output, const ExportOptions& options, Log& log,
                  json& report);

}  // namespace spx
