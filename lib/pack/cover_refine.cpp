#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <unordered_map>

#include "pack/cover.hpp"
#include "pack/median_descent.hpp"
#include "pack/sample_grid.hpp"
#include "pack/two_nearest.hpp"

namespace spx {
using detail::descend_median;
using detail::median_and_max_of;
using detail::SampleGrid;

namespace {

// The refinement's state over one pose or several: each sample's nearest and second-nearest
// sphere in its own pose, and moves of one sphere's rest centre along `directions` (the first of
// direction()'s) that cut a cost summed over the weighted samples' errors. A sphere is its rest
// centre and what spheres_at makes of it in every pose; samples are stacked pose after pose.
class OffGrid {
 public:
  OffGrid(const std::vector<std::vector<Eigen::Vector3d>>& samples, const std::vector<size_t>& weighted,
          std::vector<Eigen::Vector3d>& centers, std::vector<SphereSet>& spheres, const PoseSpheresAt& spheres_at,
          double delta, int directions)
      : directions_(directions), centers_(centers), spheres_(spheres), spheres_at_(spheres_at), delta_(delta) {
    for (size_t p = 0; p < samples.size(); ++p) {
      first_of_.push_back(uint32_t(points_.size()));
      grids_.emplace_back(samples[p], false);  // fixed cells: the moves' sums count every sample visited
      for (size_t i = 0; i < samples[p].size(); ++i) {
        points_.push_back(samples[p][i]);
        pose_.push_back(uint32_t(p));
        weighted_.push_back(i < weighted[p]);
      }
    }
    first_.assign(points_.size(), -1);
    second_.assign(points_.size(), -1);
    tbb::parallel_for(size_t(0), points_.size(), [&](size_t i) { rank(i); });
  }

  // Called after each step length's rounds (progress).
  void on_level(std::function<void()> fn) { on_level_ = std::move(fn); }

  // The weighted samples' median and largest error.
  std::pair<double, double> median_and_max() const {
    std::vector<double> e;
    for (size_t i = 0; i < points_.size(); ++i)
      if (weighted_[i]) e.push_back(gap(i, sphere(size_t(first_[i]), i)));
    return median_and_max_of(std::move(e));
  }

  // Rounds of moves by `step` (then halved down to `last`), each the one of the directions that
  // cuts the summed cost most; no sample's error rises past `ceiling` (weighted) or delta (the others).
  template <class Cost>
  size_t move_rounds(double step, double last, double ceiling, const Cost& cost) {
    size_t moves = 0;
    const size_t n = centers_.size();
    for (double s = step; s >= last; s /= 2) {
      // A sphere that found no move is not asked again until one near it (in some pose) moves:
      // the samples its moves would count are those within its radius, delta and two steps.
      std::vector<char> settled(n, 0);
      for (int round = 0; round < 3; ++round) {
        size_t this_round = 0;
        for (size_t j = 0; j < n; ++j) {
          if (settled[j]) continue;
          std::vector<Sphere> old(spheres_.size());
          for (size_t p = 0; p < old.size(); ++p) old[p] = spheres_[p][j];
          if (!move_one(j, old, s, ceiling, cost)) {
            settled[j] = 1;
            continue;
          }
          ++this_round;
          for (size_t k = 0; k < n; ++k)
            for (size_t p = 0; p < old.size() && settled[k]; ++p) {
              const Sphere &a = spheres_[p][k], &b = spheres_[p][j];
              const double reach = a.radius + 2 * delta_ + 2 * s;
              if ((a.center - old[p].center).norm() <= reach + old[p].radius ||
                  (a.center - b.center).norm() <= reach + b.radius)
                settled[k] = 0;
            }
        }
        moves += this_round;
        if (this_round == 0) break;
      }
      if (on_level_) on_level_();
    }
    return moves;
  }

 private:
  const Sphere& sphere(size_t j, size_t i) const { return spheres_[pose_[i]][j]; }
  static double gap_to(const Eigen::Vector3d& point, const Sphere& s) { return (point - s.center).norm() - s.radius; }
  double gap(size_t i, const Sphere& s) const { return gap_to(points_[i], s); }
  void rank(size_t i) {
    set_rank(i, detail::two_nearest(centers_.size(), [&](size_t j) { return gap(i, sphere(j, i)); }));
  }
  // rank(i) after sphere j alone moved from `old` (in each pose): most samples ask it alone.
  void rerank(size_t i, size_t j, const std::vector<Sphere>& old) {
    set_rank(i, detail::two_nearest_after_move({first_[i], second_[i]}, j, gap(i, old[pose_[i]]), centers_.size(),
                                               [&](size_t k) { return gap(i, sphere(k, i)); }));
  }
  void set_rank(size_t i, detail::TwoNearest t) {
    first_[i] = t.first;
    second_[i] = t.second;
  }
  double error_without(size_t i, size_t j) const {
    const int k = first_[i] == int(j) ? second_[i] : first_[i];
    return k < 0 ? std::numeric_limits<double>::infinity() : gap(i, sphere(size_t(k), i));
  }
  // The samples whose error can change with a sphere that is `s` in each pose (near it), as
  // bits, added to `marked`.
  void mark_near(const std::vector<Sphere>& s, std::vector<uint64_t>& marked) const {
    marked.resize(points_.size() / 64 + 1, 0);
    for (size_t p = 0; p < s.size(); ++p)
      grids_[p].near(s[p].center, s[p].radius + delta_, [&](uint32_t i) {
        const uint32_t n = first_of_[p] + i;
        marked[n >> 6] |= uint64_t(1) << (n & 63);
      });
  }
  // The grid cells mark_near visits for a sphere that is `s` in each pose.
  std::vector<SampleGrid::Cells> cells_near(const std::vector<Sphere>& s) const {
    std::vector<SampleGrid::Cells> out(s.size());
    for (size_t p = 0; p < s.size(); ++p) out[p] = grids_[p].cells_near(s[p].center, s[p].radius + delta_);
    return out;
  }
  // The samples near `b` (a sphere in each pose) that are not of the cells `around` (per pose),
  // ascending. A move is short: most of b's cells are its old place's, whose samples are known,
  // and only the others' are gathered and sorted (marking every sample near b in a bitmap of the
  // whole clip's and reading it back was most of a joint refinement's time over 48 frames).
  std::vector<uint32_t> more_near(const std::vector<SampleGrid::Cells>& around, const std::vector<Sphere>& b) const {
    std::vector<uint32_t> more;
    for (size_t p = 0; p < b.size(); ++p)
      grids_[p].visit_cells(grids_[p].cells_near(b[p].center, b[p].radius + delta_), around[p], [&](uint32_t i) {
        more.push_back(first_of_[p] + i);
        return false;
      });
    std::sort(more.begin(), more.end());
    return more;
  }
  static std::vector<uint32_t> set_bits(const std::vector<uint64_t>& marked) {
    std::vector<uint32_t> out;
    for (size_t w = 0; w < marked.size(); ++w)
      for (uint64_t bits = marked[w]; bits; bits &= bits - 1) out.push_back(uint32_t(w * 64 + size_t(__builtin_ctzll(bits))));
    return out;
  }

  // What every direction of one move asks of the samples near the sphere's old place, asked
  // once: each one's error, its error without the sphere, and that error's cost, and the sample
  // itself side by side with the others (the directions read them in turn). The same arithmetic
  // as asking it per direction, so the same sums to the bit.
  struct Known {
    static constexpr size_t none = size_t(-1);
    std::vector<uint32_t> samples;  // ascending
    std::vector<SampleGrid::Cells> cells;  // per pose, the cells that hold them
    std::vector<double> before, without, cost_before;
    std::vector<Eigen::Vector3d> points;
    std::vector<uint32_t> pose;
    std::vector<char> weighted;
  };
  // visit(i, k) for the samples near the sphere's old place (k: each one's place in `known`) or
  // in `more` (k: Known::none), ascending, while it returns true; false where it stopped.
  template <class Visit>
  static bool visit_either(const Known& known, const std::vector<uint32_t>& more, Visit&& visit) {
    size_t k = 0, x = 0;
    while (k < known.samples.size() || x < more.size()) {
      if (x == more.size() || (k < known.samples.size() && known.samples[k] < more[x])) {
        if (!visit(known.samples[k], k)) return false;
        ++k;
      } else if (!visit(more[x++], Known::none)) {
        return false;
      }
    }
    return true;
  }
  template <class Cost>
  Known know_around(const std::vector<Sphere>& old, size_t j, const Cost& cost) const {
    Known k;
    std::vector<uint64_t> around;
    mark_near(old, around);
    k.samples = set_bits(around);
    k.cells = cells_near(old);
    k.before.resize(k.samples.size());
    k.without.resize(k.samples.size());
    k.cost_before.resize(k.samples.size());
    k.points.resize(k.samples.size());
    k.pose.resize(k.samples.size());
    k.weighted.resize(k.samples.size());
    for (size_t n = 0; n < k.samples.size(); ++n) {
      const uint32_t i = k.samples[n];
      k.points[n] = points_[i];
      k.pose[n] = pose_[i];
      k.weighted[n] = weighted_[i];
      k.before[n] = gap(i, sphere(size_t(first_[i]), i));
      k.without[n] = error_without(i, j);
      k.cost_before[n] = weighted_[i] ? cost(k.before[n]) : 0;
    }
    return k;
  }

  template <class Cost>
  // Sphere j, `old` in each pose, moved by `s` where that cuts the cost most.
  bool move_one(size_t j, const std::vector<Sphere>& old, double s, double ceiling, const Cost& cost) {
    const Known known = know_around(old, j, cost);  // the same for every direction
    // Each direction's place and its spheres there, asked of spheres_at once per place.
    std::vector<Eigen::Vector3d> to(static_cast<size_t>(directions_));
    std::vector<const Placed*> placed(to.size(), nullptr);
    for (size_t d = 0; d < to.size(); ++d) {
      to[d] = centers_[j] + s * direction(int(d));
      const auto it = asked_.find(to[d]);
      if (it != asked_.end()) placed[d] = &it->second;
    }
    std::vector<Placed> fresh(to.size());
    std::vector<std::vector<Sphere>> moved(to.size());
    std::vector<double> change(to.size(), std::numeric_limits<double>::infinity());
    // The directions side by side: each sum is its own, the best taken in order below.
    tbb::parallel_for(0, directions_, [&](int d) {
      if (!placed[size_t(d)]) {
        Placed& f = fresh[size_t(d)];
        f.inside = spheres_at_(to[size_t(d)], f.spheres);
      }
      const Placed& here = placed[size_t(d)] ? *placed[size_t(d)] : fresh[size_t(d)];
      if (!here.inside) return;
      std::vector<Sphere>& m = moved[size_t(d)];
      m = here.spheres;
      double sum = 0;
      const bool within = visit_either(known, more_near(known.cells, m), [&](uint32_t i, size_t k) {
        const bool is_known = k != Known::none;
        const double before = is_known ? known.before[k] : gap(i, sphere(size_t(first_[i]), i));
        const double without = is_known ? known.without[k] : error_without(i, j);
        const double after = std::min(without, is_known ? gap_to(known.points[k], m[known.pose[k]]) : gap(i, m[pose_[i]]));
        const bool weighted = is_known ? known.weighted[k] : weighted_[i];
        if (after > (weighted ? ceiling : delta_) && after > before) return false;
        // An unchanged error adds exactly 0: no cost asked.
        if (weighted && after != before) sum += cost(after) - (is_known ? known.cost_before[k] : cost(before));
        return true;
      });
      if (within) change[size_t(d)] = sum;
    });
    for (size_t d = 0; d < to.size(); ++d)
      if (!placed[d]) asked_.emplace(to[d], std::move(fresh[d]));
    int best = -1;
    double best_change = -1e-12 * cost(delta_);
    for (int d = 0; d < directions_; ++d)
      if (change[size_t(d)] < best_change) {
        best_change = change[size_t(d)];
        best = d;
      }
    if (best < 0) return false;
    centers_[j] += s * direction(best);
    for (size_t p = 0; p < spheres_.size(); ++p) spheres_[p][j] = moved[size_t(best)][p];
    visit_either(known, more_near(known.cells, moved[size_t(best)]), [&](uint32_t i, size_t) {
      rerank(i, j, old);
      return true;
    });
    return true;
  }

  // Along the axes (0-5), then the cube's diagonals (6-13), each of unit length.
  static Eigen::Vector3d direction(int d) {
    Eigen::Vector3d out = Eigen::Vector3d::Zero();
    if (d < 6) {
      out[d / 2] = d % 2 ? 1 : -1;
      return out;
    }
    const int b = d - 6;
    return Eigen::Vector3d(b & 1 ? 1 : -1, b & 2 ? 1 : -1, b & 4 ? 1 : -1) / std::sqrt(3.0);
  }

  int directions_;
  std::function<void()> on_level_;
  std::vector<Eigen::Vector3d> points_;  // every pose's samples, stacked
  std::vector<uint32_t> pose_;           // per sample: its pose
  std::vector<char> weighted_;           // per sample: a vertex, whose error counts
  std::vector<uint32_t> first_of_;       // per pose: its first sample
  std::vector<SampleGrid> grids_;        // per pose
  std::vector<Eigen::Vector3d>& centers_;
  std::vector<SphereSet>& spheres_;  // per pose, per sphere
  const PoseSpheresAt& spheres_at_;
  // What spheres_at made of each place asked (a centre not moved since is asked the same moves
  // again by the later passes: the median's six ask most places several times).
  struct Placed {
    bool inside = false;
    std::vector<Sphere> spheres;
  };
  struct SameBits {
    bool operator()(const Eigen::Vector3d& a, const Eigen::Vector3d& b) const {
      return std::memcmp(a.data(), b.data(), sizeof(double) * 3) == 0;
    }
  };
  struct BitsHash {
    size_t operator()(const Eigen::Vector3d& c) const {
      uint64_t h = 0, w = 0;
      for (int k = 0; k < 3; ++k) {
        std::memcpy(&w, c.data() + k, sizeof w);
        h = (h ^ w) * 0x9E3779B97F4A7C15ull;
      }
      return size_t(h ^ (h >> 29));
    }
  };
  std::unordered_map<Eigen::Vector3d, Placed, BitsHash, SameBits> asked_;
  double delta_;
  std::vector<int> first_, second_;
};

}  // namespace

// Budget mode's refinement: the max first. Its moves cut the weighted errors summed to this
// power (relative to the largest), which the largest few dominate: a move that lowers the worst
// sample's error and raises its neighbours' a little is taken where the total would refuse it.
constexpr double kMaxPower = 128;
// Directions a centre moves along: the axes, and in budget mode the cube's diagonals too (a
// sphere between two others is often stuck along the axes alone).
constexpr int kAxes = 6, kAxesAndDiagonals = 14;
// The median's passes (each from the median the last one left): the first few make most of its
// gain (frontier-bench, the bunny at 256: 20 passes took 19 s for a median 0.005 % of the
// diagonal lower than 6 did in 7.5 s).
constexpr int kMedianPasses = 6;
constexpr const char* kRefining = "refining the centres";

size_t refine_jointly(const std::vector<std::vector<Eigen::Vector3d>>& samples, const std::vector<size_t>& weighted,
                      std::vector<Eigen::Vector3d>& centers, std::vector<SphereSet>& spheres,
                      const PoseSpheresAt& spheres_at, double delta, double step, Log& log, bool keep_max) {
  if (centers.empty() || samples.empty()) return 0;
  OffGrid state(samples, weighted, centers, spheres, spheres_at, delta, keep_max ? kAxesAndDiagonals : kAxes);
  // A percentage on a terminal, by the step lengths the passes run (the median's may end early).
  const size_t levels = keep_max ? 4 + 3 + 4 * kMedianPasses : 3;
  size_t done = 0;
  state.on_level([&] { log.progress(kRefining, std::min(++done, levels - 1), levels); });
  if (!keep_max) {
    // Tolerance mode: the total, no sample leaving delta.
    const size_t moves = state.move_rounds(step, step / 4, delta, [](double e) { return e; });
    log.progress(kRefining, levels, levels);
    log.detail("refined centres: " + std::to_string(moves) + " moves");
    return moves;
  }
  // The max, down to an eighth of the step.
  const double top = std::max(state.median_and_max().second, 1e-300);
  const size_t for_max = state.move_rounds(
      step, step / 8, top, [&](double e) { return std::pow(std::max(e, 0.0) / top, kMaxPower); });
  // Then the total and the median (as median_descent does with the candidates), neither raising
  // a weighted sample's error past the largest now.
  const double ceiling = state.median_and_max().second;
  const size_t for_total = state.move_rounds(step, step / 4, ceiling, [](double e) { return e; });
  const size_t for_median = descend_median(
      state.median_and_max().first, delta, kMedianPasses,
      [&](const auto& cost) { return state.move_rounds(step, step / 8, ceiling, cost); },
      [&] { return state.median_and_max().first; });
  log.progress(kRefining, levels, levels);
  log.detail("refined centres: " + std::to_string(for_max) + " moves for the max, " + std::to_string(for_total) +
             " for the total, " + std::to_string(for_median) + " for the median");
  return for_max + for_total + for_median;
}

size_t refine_off_grid(const std::vector<Eigen::Vector3d>& samples, size_t weighted, SphereSet& spheres,
                       const std::function<double(const Eigen::Vector3d&)>& radius_at, double delta, double step,
                       Log& log, bool keep_max) {
  // One pose, the rest: a sphere is its centre and the radius there.
  std::vector<Eigen::Vector3d> centers;
  for (const Sphere& s : spheres) centers.push_back(s.center);
  std::vector<SphereSet> one{spheres};
  const PoseSpheresAt at = [&](const Eigen::Vector3d& c, std::vector<Sphere>& out) {
    const double r = radius_at(c);
    if (!(r > 0)) return false;
    out.assign(1, Sphere{c, r});
    return true;
  };
  const size_t moves = refine_jointly({samples}, {weighted}, centers, one, at, delta, step, log, keep_max);
  spheres = std::move(one[0]);
  return moves;
}

}  // namespace spx
