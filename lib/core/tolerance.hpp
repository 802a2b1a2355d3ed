#pragma once
// A length given as mesh units or as a percentage of the mesh's bounding-box diagonal.
#include <string>

namespace spx {

struct Tolerance {
  double value = 0;
  bool percent = false;
  bool set() const { return value > 0; }
  double length(double diagonal) const { return percent ? value / 100 * diagonal : value; }
};

// "0.05" (mesh units) or "1%"; empty: not set. Throws a usage error naming `option`.
Tolerance parse_tolerance(const std::string& text, const std::string& option);

}  // namespace spx
