#pragma once
// Numbers in messages: %g, so 1.5e-05 and 0.0417 read as written, never "0.000000".
#include <cstdio>
#include <string>

namespace spx {

inline std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}

}  // namespace spx
