#pragma once
// proxy-export, the tool: a proxy to the runtime .spx, a plain JSON dump, GLB/PLY previews
// (coloured by error when the meshes are given), glTF physics colliders, or a page that plays it.
#include "core/json_io.hpp"
#include "core/log.hpp"

#include <string>
#include <vector>

namespace spx {

struct ExportOptions {
  int pose = -1;         // .ply: the pose written (-1: not given, the rest)
  bool stacked = false;  // .glb: poses in place (by default side by side)
  // With the meshes, .glb/.ply previews also show each pose's mesh coloured by its error.
  std::string rest;
  std::vector<std::string> poses;
  // .glb: the spheres as glTF physics colliders (KHR_physics_rigid_bodies, OMI_physics_body),
  // into `asset` (a glTF of the body, which comes along) when given.
  bool physics = false;
  std::string asset;
  std::string mesh;  // .html with `asset`: one mesh (or node) of it by name, as pose-extract --mesh
  // .html: the ground plane's normal, "y" or "z" (empty: y with an asset or a manifest, z with
  // meshes given by --rest).
  std::string up;
  std::string manifest;  // where rest and poses came from: pose-extract's poses.json (empty: --rest/--pose)
};

// proxy-export IN.proxy.json -o OUT.spx | OUT.json | OUT.glb | OUT.ply, or -o OUT.glb --physics [--asset A],
// or -o OUT.html [--asset A | --rest R --pose P...]: a page that plays the proxy.
void proxy_export_files(const std::string& input, const std::string& output, const ExportOptions& options, Log& log,
                  json& report);

}  // namespace spx
