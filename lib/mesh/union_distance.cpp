#include "mesh/union_distance.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace spx {

std::vector<double> union_signed_distance(const std::vector<Eigen::Vector3d>& points, const SphereSet& spheres) {
  std::vector<double> out(points.size(), std::numeric_limits<double>::infinity());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, points.size(), 256), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t i = r.begin(); i != r.end(); ++i) {
      double best = std::numeric_limits<double>::infinity();
      for (const auto& s : spheres)
        if (s.radius > 0) best = std::min(best, (points[i] - s.center).norm() - s.radius);
      out[i] = best;
    }
  });
  return out;
}

ErrorStats summarize_abs(const std::vector<double>& values) {
  ErrorStats s;
  s.count = values.size();
  if (values.empty()) return s;
  std::vector<double> a(values.size());
  std::transform(values.begin(), values.end(), a.begin(), [](double v) { return std::abs(v); });
  std::sort(a.begin(), a.end());
  auto quantile = [&](double q) {
    const double pos = q * double(a.size() - 1);
    const size_t lo = size_t(std::floor(pos));
    const size_t hi = std::min(lo + 1, a.size() - 1);
    return a[lo] + (pos - double(lo)) * (a[hi] - a[lo]);
  };
  s.median = quantile(0.5);
  s.p95 = quantile(0.95);
  s.max = a.back();
  return s;
}

}  // namespace spx
