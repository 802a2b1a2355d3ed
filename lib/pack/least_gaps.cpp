// Each sample's least gap to any candidate (least_gaps, least_gaps_of in pack/coverage.hpp): a
// grid search by radius class, the same gaps to the bit as a scan of every candidate.
#include "pack/coverage.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

#include "pack/sample_grid.hpp"

namespace spx {
using detail::SampleGrid;

namespace {

// One pose's candidates by radius class (radii within a factor of 2 of the class's largest),
// each class's centres on a grid: a sphere whose centre is farther from p than the best gap so
// far plus its class's largest radius cannot lower it, so each class is asked only for the
// centres that near. The least gap is the same minimum of the same sums as a scan of them all.
class LeastGapSearch {
 public:
  explicit LeastGapSearch(const SphereSet& spheres) : spheres_(spheres) {
    double largest = 0;
    for (const Sphere& s : spheres) largest = std::max(largest, s.radius);
    std::vector<std::vector<Eigen::Vector3d>> centres;
    for (size_t i = 0; i < spheres.size(); ++i) {
      if (!(spheres[i].radius > 0)) continue;
      const size_t k = size_t(std::clamp(std::floor(std::log2(largest / spheres[i].radius)), 0.0, 60.0));
      if (k >= classes_.size()) classes_.resize(k + 1), centres.resize(k + 1);
      classes_[k].members.push_back(uint32_t(i));
      classes_[k].largest = std::max(classes_[k].largest, spheres[i].radius);
      classes_[k].box.extend(spheres[i].center);
      centres[k].push_back(spheres[i].center);
    }
    for (size_t k = 0; k < classes_.size(); ++k) classes_[k].grid = std::make_unique<SampleGrid>(centres[k]);
    margin_ = 1e-9 * (largest + 1);
  }

  double least_gap(const Eigen::Vector3d& p) const {
    double best = std::numeric_limits<double>::infinity();
    auto ask = [&](const Class& c, double reach) {
      // No farther than the class's farthest centre (an infinite reach would not index the grid).
      const double whole = (c.box.max() - p).cwiseAbs().cwiseMax((c.box.min() - p).cwiseAbs()).norm();
      c.grid->near(p, std::min(reach, whole), [&](uint32_t n) {
        const Sphere& s = spheres_[c.members[n]];
        best = std::min(best, (p - s.center).norm() - s.radius);
      });
    };
    // Smallest radii first, each class within twice its radius (a sample's own tangent ball is
    // there); then again, farther, where the best gap found allows a nearer one beyond that.
    const double slack = margin_ * (1 + p.lpNorm<Eigen::Infinity>());
    uint64_t again = 0;  // one bit per class (at most 61)
    for (size_t k = classes_.size(); k-- > 0;) {
      const Class& c = classes_[k];
      if (c.members.empty()) continue;
      const double needed = best + c.largest + slack;
      ask(c, std::min(needed, 2 * c.largest));
      if (!(needed <= 2 * c.largest)) again |= uint64_t(1) << k;
    }
    for (size_t k = 0; k < classes_.size(); ++k)
      if (again >> k & 1) ask(classes_[k], best + classes_[k].largest + slack);
    return best;
  }

 private:
  struct Class {
    std::vector<uint32_t> members;  // sphere indices
    double largest = 0;
    Eigen::AlignedBox3d box;           // of the members' centres
    std::unique_ptr<SampleGrid> grid;  // over them
  };
  const SphereSet& spheres_;
  std::vector<Class> classes_;
  double margin_ = 0;  // far above the sums' rounding
};

constexpr size_t kScannedBelow = 64;  // samples of one pose

}  // namespace

std::vector<double> least_gaps_of(const CoverProblem& problem, const std::vector<uint32_t>& samples) {
  std::vector<uint32_t> pose_start(1, 0);
  for (const auto& points : problem.samples) pose_start.push_back(pose_start.back() + uint32_t(points.size()));
  auto pose_of = [&](uint32_t sample) {
    return size_t(std::upper_bound(pose_start.begin(), pose_start.end(), sample) - pose_start.begin()) - 1;
  };
  // A pose asked for a few samples is scanned: its grids would cost more than the scan.
  std::vector<size_t> asked(problem.spheres.size(), 0);
  for (uint32_t s : samples) ++asked[pose_of(s)];
  std::vector<std::unique_ptr<LeastGapSearch>> search(problem.spheres.size());
  tbb::parallel_for(size_t(0), search.size(), [&](size_t k) {
    if (asked[k] >= kScannedBelow) search[k] = std::make_unique<LeastGapSearch>(problem.spheres[k]);
  });
  std::vector<double> gaps(samples.size(), std::numeric_limits<double>::infinity());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, samples.size(), 64), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t i = r.begin(); i != r.end(); ++i) {
      const size_t k = pose_of(samples[i]);
      const Eigen::Vector3d& p = problem.samples[k][samples[i] - pose_start[k]];
      if (search[k]) {
        gaps[i] = search[k]->least_gap(p);
        continue;
      }
      for (const Sphere& s : problem.spheres[k])
        if (s.radius > 0) gaps[i] = std::min(gaps[i], (p - s.center).norm() - s.radius);
    }
  });
  return gaps;
}

std::vector<double> least_gaps(const CoverProblem& problem) {
  std::vector<uint32_t> all(problem.sample_count());
  for (size_t i = 0; i < all.size(); ++i) all[i] = uint32_t(i);
  return least_gaps_of(problem, all);
}

}  // namespace spx
