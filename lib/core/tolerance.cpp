#include "core/tolerance.hpp"

#include <cmath>
#include <stdexcept>

#include "core/error.hpp"

namespace spx {

Tolerance parse_tolerance(const std::string& text, const std::string& option) {
  Tolerance t;
  if (text.empty()) return t;
  std::string number = text;
  if (number.back() == '%') {
    t.percent = true;
    number.pop_back();
  }
  size_t used = 0;
  try {
    t.value = std::stod(number, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != number.size() || number.empty() || !(t.value > 0) || !std::isfinite(t.value))
    fail_usage(option, "'" + text + "' is not a positive length or percentage (e.g. 0.05 or 1%)");
  return t;
}

}  // namespace spx
