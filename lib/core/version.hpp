#pragma once
// The project's version, as every tool, generated file and report names it.
namespace spx {

const char* version_string();

}  // namespace spx
