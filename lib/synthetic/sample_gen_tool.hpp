#pragma once
// sample-gen, the tool: the project's own assets written to a folder.
#include <string>

#include "core/json_io.hpp"
#include "core/log.hpp"

namespace spx {

// sample-gen NAME -o DIR: rest.obj, one OBJ per pose and NAME-morph.glb with the poses as morph
// targets and a clip that reaches each in turn; for "robot", robot.glb alone.
void sample_gen_files(const std::string& name, const std::string& dir, Log& log, json& report);

}  // namespace spx
