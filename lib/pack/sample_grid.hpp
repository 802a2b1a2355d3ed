#pragma once
// pack internals: samples bucketed on a uniform grid, for ball queries (the coverage rows and
// the centre refinement).
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <vector>

namespace spx::detail {

constexpr double kCellsAcross = 40;  // cells along the samples' bounding-box diagonal

class SampleGrid {
 public:
  // `by_density`: cells no smaller than the box's volume per sample either, so that a few samples
  // scattered over a large box (a frame's bare samples) do not leave a ball query most of its
  // cells to visit empty. The samples within reach are visited either way; the others visited
  // (a little farther) differ.
  explicit SampleGrid(const std::vector<Eigen::Vector3d>& points, bool by_density = true) {
    for (const auto& p : points) box_.extend(p);
    const double diag = std::max(box_.diagonal().norm(), 1e-30);
    cell_ = diag / kCellsAcross;
    if (by_density && !points.empty()) cell_ = std::max(cell_, std::cbrt(box_.volume() / double(points.size())));
    dims_ = ((box_.sizes() / cell_).array().floor() + 1).cast<int>().cwiseMax(1);
    std::vector<uint32_t> count(cells() + 1, 0);
    for (const auto& p : points) ++count[cell_of(p) + 1];
    std::partial_sum(count.begin(), count.end(), count.begin());
    start_ = count;
    order_.resize(points.size());
    for (size_t i = 0; i < points.size(); ++i) order_[count[cell_of(points[i])]++] = uint32_t(i);
  }
  // Calls visit(i) for every sample within `reach` of c (and some a little farther).
  template <class Visit>
  void near(const Eigen::Vector3d& c, double reach, Visit&& visit) const {
    any_near(c, reach, [&](uint32_t i) {
      visit(i);
      return false;
    });
  }
  // Whether found(i) holds for some sample within `reach` of c (or a little farther): the
  // samples visited as near() does, until the first that does.
  template <class Found>
  bool any_near(const Eigen::Vector3d& c, double reach, Found&& found) const {
    return visit_cells(cells_near(c, reach), Cells{}, found);
  }

  // A box of cells, inclusive; empty where lo > hi on some axis.
  struct Cells {
    Eigen::Vector3i lo = Eigen::Vector3i::Zero(), hi = Eigen::Vector3i::Constant(-1);
    bool contains(int i, int j, int k) const {
      return i >= lo.x() && i <= hi.x() && j >= lo.y() && j <= hi.y() && k >= lo.z() && k <= hi.z();
    }
  };
  // The cells near() visits for a ball.
  Cells cells_near(const Eigen::Vector3d& c, double reach) const {
    // A ball clear of the samples' box meets none (the cells clamp to the box's edge).
    if (((c - box_.min()).array() < -reach).any() || ((c - box_.max()).array() > reach).any()) return {};
    return {index(c - Eigen::Vector3d::Constant(reach)), index(c + Eigen::Vector3d::Constant(reach))};
  }
  // found(i) for the samples of the cells in `box` but not in `skip`, until it holds for one.
  template <class Found>
  bool visit_cells(const Cells& box, const Cells& skip, Found&& found) const {
    for (int i = box.lo.x(); i <= box.hi.x(); ++i)
      for (int j = box.lo.y(); j <= box.hi.y(); ++j)
        for (int k = box.lo.z(); k <= box.hi.z(); ++k) {
          if (skip.contains(i, j, k)) continue;
          const size_t cell = size_t(i) + size_t(dims_.x()) * (size_t(j) + size_t(dims_.y()) * size_t(k));
          for (uint32_t n = start_[cell]; n < start_[cell + 1]; ++n)
            if (found(order_[n])) return true;
        }
    return false;
  }

 private:
  size_t cells() const { return size_t(dims_.x()) * size_t(dims_.y()) * size_t(dims_.z()); }
  // Clamped before the cast: a ball whose reach dwarfs the box (a tolerance of 1e9) has corners
  // past any int, where the cast would wrap to the box's first cell and miss the others.
  Eigen::Vector3i index(const Eigen::Vector3d& p) const {
    return ((p - box_.min()) / cell_).array().floor().max(0.0).min((dims_.array() - 1).cast<double>()).cast<int>();
  }
  size_t cell_of(const Eigen::Vector3d& p) const {
    const Eigen::Vector3i c = index(p);
    return size_t(c.x()) + size_t(dims_.x()) * (size_t(c.y()) + size_t(dims_.y()) * size_t(c.z()));
  }
  Eigen::AlignedBox3d box_;
  double cell_ = 1;
  Eigen::Vector3i dims_;
  std::vector<uint32_t> start_, order_;
};

}  // namespace spx::detail
