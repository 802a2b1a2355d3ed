#pragma once
// pack internals: the median's descent, shared by the cover's swaps (cover_improve.cpp) and the
// centres' moves (cover_refine.cpp).
#include <algorithm>
#include <utility>
#include <vector>

namespace spx::detail {

// The median and largest of these errors (0 and 0 for none).
inline std::pair<double, double> median_and_max_of(std::vector<double> errors) {
  if (errors.empty()) return {0, 0};
  const double largest = *std::max_element(errors.begin(), errors.end());
  std::nth_element(errors.begin(), errors.begin() + long(errors.size() / 2), errors.end());
  return {errors[errors.size() / 2], largest};
}

// Passes for the median, by swaps or by moves alike: each pass(cost) lowers a cost counting the
// errors above the median it starts from (the summed error breaks ties) and returns the changes
// made; again from the new median (median_now()) while it falls, at most `passes` times.
// Returns the changes made.
template <class Pass, class Median>
size_t descend_median(double median, double delta, int passes, const Pass& pass, const Median& median_now) {
  const double tie = 1e-7 / delta;  // errors are at most 2 delta: under one sample for 5 million of them
  size_t changes = 0;
  for (int n = 0; n < passes; ++n) {
    const double tau = median;
    const size_t made = pass([&](double e) { return (e > tau ? 1.0 : 0.0) + tie * e; });
    changes += made;
    const double now = median_now();
    if (made == 0 || !(now < median)) break;
    median = now;
  }
  return changes;
}

}  // namespace spx::detail
