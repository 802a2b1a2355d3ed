#pragma once
// A length given as mesh units or as a percentage of the mesh's bounding-box diagonal.
namespace spx {

struct Tolerance {
  double value = 0;
  bool percent = false;
  bool set() const { return value > 0; }
  double length(double diagonal) const { return percent ? value / 100 * diagonal : value; }
};

}  // namespace spx
