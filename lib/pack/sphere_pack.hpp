#pragma once
#include "core/json_io.hpp"
#include "core/log.hpp"
#include "pack/pack.hpp"

namespace spx {

// "0.05" (mesh units) or "1%" (of the mesh's bounding-box diagonal); empty: none.
struct Tolerance {
  double value = 0;
  bool percent = false;
  bool set() const { return value > 0; }
};
Tolerance parse_tolerance(const std::string& text);

// sphere-pack IN.vdb -o OUT.spheres.json [--mesh REST] [--tolerance T]
void sphere_pack(const std::string& input, const std::string& mesh_path, const std::string& output,
                 const PackOptions& options, const Tolerance& tolerance, Log& log, json& report);

}  // namespace spx
