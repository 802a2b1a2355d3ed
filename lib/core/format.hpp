#pragma once
// Numbers in messages: %g, so 1.5e-05 and 0.0417 read as written, never "0.000000"; counts
// with their nouns.
#include <cstdio>
#include <string>

namespace spx {

inline std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}

// "1 pose", "3 poses": a count and its noun, which takes an s unless the count is one.
inline std::string counted(size_t n, const std::string& noun) { return std::to_string(n) + " " + noun + (n == 1 ? "" : "s"); }

}  // namespace spx
