#pragma once
// The project's version, as every tool, generated file and report names it.
#include <string>

namespace spx {

const char* version_string();

// The running program's GNU build ID, in hex (empty where the linker wrote none): it changes with
// any change to the code linked in, so files kept between runs (the tools' caches) are keyed on it.
const std::string& build_identity();

}  // namespace spx
