#pragma once
// The folder the tools keep files in between runs (`--cache`): what no tolerance or budget
// changes, in files named by a key of what they were made from.
#include <cstdint>
#include <string>

namespace spx {

// `dir` made with its parents where it is not there; throws Error(cannot_write) naming it where it
// cannot be (a file in its place).
void make_cache_folder(const std::string& dir);

// A key (a hash of what a file was made from) as the 16 hex digits of its name.
std::string cache_key_text(uint64_t hash);

}  // namespace spx
