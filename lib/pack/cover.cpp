#include "pack/cover.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <memory>
#include <numeric>
#include <queue>
#include <tuple>

#include "core/format.hpp"

namespace spx {
namespace {

// Deterministic on every platform (std's distributions are not).
struct SplitMix {
  uint64_t state;
  uint64_t next() {
    uint64_t z = (state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  double uniform() { return double(next() >> 11) * 0x1.0p-53; }
};

// Samples of one pose bucketed on a uniform grid, for ball queries.
class SampleGrid {
 public:
  explicit SampleGrid(const std::vector<Eigen::Vector3d>& points) : points_(points) {
    for (const auto& p : points) box_.extend(p);
    const double diag = std::max(box_.diagonal().norm(), 1e-30);
    cell_ = diag / 40;
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
    const Eigen::Vector3i lo = index(c - Eigen::Vector3d::Constant(reach)), hi = index(c + Eigen::Vector3d::Constant(reach));
    for (int i = lo.x(); i <= hi.x(); ++i)
      for (int j = lo.y(); j <= hi.y(); ++j)
        for (int k = lo.z(); k <= hi.z(); ++k) {
          const size_t cell = size_t(i) + size_t(dims_.x()) * (size_t(j) + size_t(dims_.y()) * size_t(k));
          for (uint32_t n = start_[cell]; n < start_[cell + 1]; ++n) visit(order_[n]);
        }
  }

 private:
  size_t cells() const { return size_t(dims_.x()) * size_t(dims_.y()) * size_t(dims_.z()); }
  Eigen::Vector3i index(const Eigen::Vector3d& p) const {
    return ((p - box_.min()) / cell_).array().floor().cast<int>().max(0).min(dims_.array() - 1);
  }
  size_t cell_of(const Eigen::Vector3d& p) const {
    const Eigen::Vector3i c = index(p);
    return size_t(c.x()) + size_t(dims_.x()) * (size_t(c.y()) + size_t(dims_.y()) * size_t(c.z()));
  }
  const std::vector<Eigen::Vector3d>& points_;
  Eigen::AlignedBox3d box_;
  double cell_ = 1;
  Eigen::Vector3i dims_;
  std::vector<uint32_t> start_, order_;
};

// Keeps the deepest voxel of each cell of `stride` voxels (ties to the lower index).
std::vector<size_t> thin_on_grid(const std::vector<size_t>& voxels, const DenseField& field, int stride) {
  std::vector<std::pair<uint64_t, size_t>> keyed;
  keyed.reserve(voxels.size());
  const GridShape& g = field.shape;
  const uint64_t ny = uint64_t(g.dims.y() / stride + 1), nz = uint64_t(g.dims.z() / stride + 1);
  for (size_t idx : voxels) {
    const Eigen::Vector3i c = g.coords(idx) / stride;
    keyed.emplace_back((uint64_t(c.x()) * ny + uint64_t(c.y())) * nz + uint64_t(c.z()), idx);
  }
  std::sort(keyed.begin(), keyed.end(), [&](const auto& a, const auto& b) {
    if (a.first != b.first) return a.first < b.first;
    if (field.values[a.second] != field.values[b.second]) return field.values[a.second] < field.values[b.second];
    return a.second < b.second;
  });
  std::vector<size_t> out;
  for (size_t n = 0; n < keyed.size(); ++n)
    if (n == 0 || keyed[n].first != keyed[n - 1].first) out.push_back(keyed[n].second);
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace

SphereSet inscribed_candidates(const DenseField& field, const MeshQuery& mesh, const CandidateOptions& opt) {
  const GridShape& g = field.shape;
  const double h = g.voxel_size;
  // Near-medial: off the medial axis, the distance grows by about h/sqrt(3) or more towards
  // some face neighbour; on it (and across a part a few voxels thin) no neighbour is deeper.
  std::vector<char> medial(g.count(), 0);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, g.count(), 4096), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t idx = r.begin(); idx != r.end(); ++idx) {
      const float v = field.values[idx];
      if (!(v < 0)) continue;
      bool deeper = false;
      g.for_each_face_neighbour(idx, g.coords(idx), [&](size_t m) { deeper = deeper || field.values[m] <= v - 0.5f * float(h); });
      medial[idx] = !deeper;
    }
  });
  std::vector<size_t> voxels;
  for (size_t idx = 0; idx < g.count(); ++idx)
    if (medial[idx]) voxels.push_back(idx);
  for (int stride = 2; voxels.size() > opt.max_candidates && stride < 64; ++stride) voxels = thin_on_grid(voxels, field, stride);

  SphereSet out(voxels.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, voxels.size(), 64), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t n = r.begin(); n != r.end(); ++n) {
      const Eigen::Vector3d c = g.world(voxels[n]);
      double radius = mesh.inside(c) ? std::min(opt.max_radius, mesh.distance(c)) : 0.0;
      if (opt.field_bounds_radius) radius = std::min(radius, -double(field.values[voxels[n]]) - 0.1 * h);
      out[n] = {c, std::max(radius, 0.0)};
      if (!opt.field_bounds_radius) out[n] = grow_inscribed(mesh, out[n], opt.max_radius, opt.growth);
    }
  });
  out.erase(std::remove_if(out.begin(), out.end(),
                           [&](const Sphere& s) { return !(s.radius > 0) || s.radius < opt.min_radius; }),
            out.end());
  return out;
}

std::vector<Eigen::Vector3d> surface_samples(const TriMesh& mesh, size_t area_samples, uint64_t seed) {
  std::vector<Eigen::Vector3d> out = mesh.vertices;
  std::vector<double> cumulative(mesh.triangles.size());
  double total = 0;
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const Eigen::Vector3i& f = mesh.triangles[t];
    total += 0.5 * (mesh.vertices[size_t(f[1])] - mesh.vertices[size_t(f[0])])
                       .cross(mesh.vertices[size_t(f[2])] - mesh.vertices[size_t(f[0])])
                       .norm();
    cumulative[t] = total;
  }
  if (!(total > 0)) return out;
  SplitMix rng{seed};
  for (size_t n = 0; n < area_samples; ++n) {
    const double pick = rng.uniform() * total;
    const size_t t = std::min(size_t(std::upper_bound(cumulative.begin(), cumulative.end(), pick) - cumulative.begin()),
                              cumulative.size() - 1);
    const double a = std::sqrt(rng.uniform()), b = rng.uniform();
    const Eigen::Vector3i& f = mesh.triangles[t];
    out.push_back((1 - a) * mesh.vertices[size_t(f[0])] + a * (1 - b) * mesh.vertices[size_t(f[1])] +
                  a * b * mesh.vertices[size_t(f[2])]);
  }
  return out;
}

size_t CoverProblem::sample_count() const {
  size_t n = 0;
  for (const auto& s : samples) n += s.size();
  return n;
}

namespace {

// Every (candidate, sample) pair within `delta`, gathered per candidate by `keep(row, sample,
// gap)` in parallel over candidates; each row then sorted.
template <class Entry, class Keep>
std::vector<std::vector<Entry>> gather_rows(const CoverProblem& problem, double delta, std::vector<uint32_t>& offset,
                                            Keep&& keep) {
  const size_t candidates = problem.candidate_count();
  std::vector<SampleGrid> grids;
  offset.assign(1, 0);
  for (const auto& s : problem.samples) {
    grids.emplace_back(s);
    offset.push_back(offset.back() + uint32_t(s.size()));
  }
  std::vector<std::vector<Entry>> rows(candidates);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, candidates, 16), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t c = r.begin(); c != r.end(); ++c) {
      for (size_t k = 0; k < problem.samples.size(); ++k) {
        const Sphere& s = problem.spheres[k][c];
        if (!(s.radius > 0)) continue;
        const auto& points = problem.samples[k];
        grids[k].near(s.center, s.radius + delta, [&](uint32_t i) {
          const double gap = (points[i] - s.center).norm() - s.radius;
          if (gap <= delta) keep(rows[c], offset[k] + i, gap);
        });
      }
      std::sort(rows[c].begin(), rows[c].end());
    }
  });
  return rows;
}

}  // namespace

Coverage coverage_at(const CoverProblem& problem, double delta) {
  std::vector<uint32_t> offset;
  std::vector<std::vector<uint32_t>> rows = gather_rows<uint32_t>(
      problem, delta, offset, [](std::vector<uint32_t>& row, uint32_t sample, double) { row.push_back(sample); });
  Coverage cov;
  cov.sample_count = offset.back();
  cov.start.assign(rows.size() + 1, 0);
  for (size_t c = 0; c < rows.size(); ++c) cov.start[c + 1] = cov.start[c] + uint32_t(rows[c].size());
  cov.samples.resize(cov.start.back());
  tbb::parallel_for(size_t(0), rows.size(),
                    [&](size_t c) { std::copy(rows[c].begin(), rows[c].end(), cov.samples.begin() + cov.start[c]); });
  return cov;
}

GapTable::GapTable(const CoverProblem& problem, double max_delta) : max_delta_(max_delta) {
  std::vector<uint32_t> offset;
  const std::vector<std::vector<std::pair<uint32_t, double>>> rows = gather_rows<std::pair<uint32_t, double>>(
      problem, max_delta, offset,
      [](std::vector<std::pair<uint32_t, double>>& row, uint32_t sample, double gap) { row.emplace_back(sample, gap); });
  const size_t candidates = rows.size();
  sample_count_ = offset.back();
  start_.assign(candidates + 1, 0);
  for (size_t c = 0; c < candidates; ++c) start_[c + 1] = start_[c] + uint32_t(rows[c].size());
  samples_.resize(start_.back());
  gaps_.resize(start_.back());
  tbb::parallel_for(size_t(0), candidates, [&](size_t c) {
    for (size_t n = 0; n < rows[c].size(); ++n) std::tie(samples_[start_[c] + n], gaps_[start_[c] + n]) = rows[c][n];
  });
}

Coverage GapTable::at(double delta) const {
  delta = std::min(delta, max_delta_);
  Coverage cov;
  cov.sample_count = sample_count_;
  cov.start.reserve(start_.size());
  cov.start.push_back(0);
  for (size_t c = 0; c + 1 < start_.size(); ++c) {
    for (uint32_t n = start_[c]; n < start_[c + 1]; ++n)
      if (gaps_[n] <= delta) cov.samples.push_back(samples_[n]);
    cov.start.push_back(uint32_t(cov.samples.size()));
  }
  return cov;
}

std::vector<double> least_gaps(const CoverProblem& problem) {
  std::vector<double> out;
  for (size_t k = 0; k < problem.samples.size(); ++k) {
    const auto& points = problem.samples[k];
    const SphereSet& spheres = problem.spheres[k];
    std::vector<double> gaps(points.size(), std::numeric_limits<double>::infinity());
    tbb::parallel_for(tbb::blocked_range<size_t>(0, points.size(), 64), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t i = r.begin(); i != r.end(); ++i)
        for (const Sphere& s : spheres)
          if (s.radius > 0) gaps[i] = std::min(gaps[i], (points[i] - s.center).norm() - s.radius);
    });
    out.insert(out.end(), gaps.begin(), gaps.end());
  }
  return out;
}

std::vector<int> greedy_cover(const Coverage& cov) {
  const size_t candidates = cov.start.size() - 1;
  std::vector<char> covered(cov.sample_count, 0);
  // Samples few candidates cover weigh more: a sphere that takes the only cover of a hard
  // sample early saves the spheres that would chase it late.
  std::vector<uint32_t> degree(cov.sample_count, 0);
  for (uint32_t s : cov.samples) ++degree[s];
  std::vector<double> weight(cov.sample_count, 0);
  for (size_t s = 0; s < weight.size(); ++s) weight[s] = degree[s] ? 1.0 / degree[s] : 0;
  // Lazy greedy: a popped gain is recounted, and the candidate taken only if it still leads.
  std::priority_queue<std::pair<double, int>> queue;  // (gain, -index)
  auto gain_of = [&](size_t c) {
    double g = 0;
    for (uint32_t n = cov.start[c]; n < cov.start[c + 1]; ++n)
      if (!covered[cov.samples[n]]) g += weight[cov.samples[n]];
    return g;
  };
  for (size_t c = 0; c < candidates; ++c)
    if (cov.row_size(c) > 0) queue.emplace(gain_of(c), -int(c));
  std::vector<int> chosen;
  while (!queue.empty()) {
    const auto [gain, neg] = queue.top();
    queue.pop();
    const size_t c = size_t(-neg);
    const double now = gain_of(c);
    if (!(now > 0)) continue;
    if (now < gain) {
      queue.emplace(now, neg);
      continue;
    }
    chosen.push_back(int(c));
    for (uint32_t n = cov.start[c]; n < cov.start[c + 1]; ++n) covered[cov.samples[n]] = 1;
  }
  // Redundant spheres, smallest first: every sample also covered by another chosen sphere.
  std::vector<uint32_t> times(cov.sample_count, 0);
  for (int c : chosen)
    for (uint32_t n = cov.start[size_t(c)]; n < cov.start[size_t(c) + 1]; ++n) ++times[cov.samples[n]];
  std::vector<int> order(chosen);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return cov.row_size(size_t(a)) < cov.row_size(size_t(b)); });
  std::vector<char> dropped(candidates, 0);
  for (int c : order) {
    bool redundant = true;
    for (uint32_t n = cov.start[size_t(c)]; n < cov.start[size_t(c) + 1] && redundant; ++n)
      redundant = times[cov.samples[n]] >= 2;
    if (!redundant) continue;
    dropped[size_t(c)] = 1;
    for (uint32_t n = cov.start[size_t(c)]; n < cov.start[size_t(c) + 1]; ++n) --times[cov.samples[n]];
  }
  chosen.erase(std::remove_if(chosen.begin(), chosen.end(), [&](int c) { return dropped[size_t(c)]; }), chosen.end());
  return chosen;
}

size_t shrink_cover(const Coverage& cov, std::vector<int>& chosen) {
  const size_t candidates = cov.start.size() - 1;
  std::vector<char> in(candidates, 0);
  std::vector<uint32_t> times(cov.sample_count, 0);
  for (int c : chosen) {
    in[size_t(c)] = 1;
    for (uint32_t n = cov.start[size_t(c)]; n < cov.start[size_t(c) + 1]; ++n) ++times[cov.samples[n]];
  }
  auto account = [&](uint32_t c, int by) {
    for (uint32_t n = cov.start[c]; n < cov.start[c + 1]; ++n) times[cov.samples[n]] = uint32_t(int(times[cov.samples[n]]) + by);
  };
  auto redundant = [&](uint32_t c) {
    for (uint32_t n = cov.start[c]; n < cov.start[c + 1]; ++n)
      if (times[cov.samples[n]] < 2) return false;
    return true;
  };
  // The chosen sphere that alone covers each sample (-1: none or several), and how many such
  // samples each sphere has: a candidate makes sphere k redundant only if it covers all of k's.
  std::vector<int> owner(cov.sample_count, -1);
  std::vector<uint32_t> critical(candidates, 0);
  auto find_owners = [&] {
    std::fill(owner.begin(), owner.end(), -1);
    std::fill(critical.begin(), critical.end(), 0);
    for (size_t c = 0; c < candidates; ++c)
      if (in[c])
        for (uint32_t n = cov.start[c]; n < cov.start[c + 1]; ++n)
          if (times[cov.samples[n]] == 1) {
            owner[cov.samples[n]] = int(c);
            ++critical[c];
          }
  };
  find_owners();
  // Add one candidate, drop the spheres it makes redundant; keep the move when two or more go.
  size_t shrunk = 0;
  std::vector<uint32_t> hits(candidates, 0);
  for (int pass = 0; pass < 3; ++pass) {
    size_t this_pass = 0;
    for (uint32_t c = 0; c < candidates; ++c) {
      if (in[c] || cov.row_size(c) == 0) continue;
      std::vector<uint32_t> touched;
      for (uint32_t n = cov.start[c]; n < cov.start[c + 1]; ++n) {
        const int k = owner[cov.samples[n]];
        if (k < 0) continue;
        if (hits[size_t(k)]++ == 0) touched.push_back(uint32_t(k));
      }
      std::vector<uint32_t> could;
      for (uint32_t k : touched) {
        if (hits[k] == critical[k]) could.push_back(k);
        hits[k] = 0;
      }
      if (could.size() < 2) continue;
      account(c, +1);
      std::vector<uint32_t> dropped;
      for (uint32_t k : could)
        if (redundant(k)) {
          account(k, -1);
          in[k] = 0;
          dropped.push_back(k);
        }
      if (dropped.size() >= 2) {
        in[c] = 1;
        ++this_pass;
        find_owners();
        continue;
      }
      for (uint32_t k : dropped) {
        account(k, +1);
        in[k] = 1;
      }
      account(c, -1);
    }
    shrunk += this_pass;
    if (this_pass == 0) break;
  }
  if (shrunk > 0) {
    chosen.clear();
    for (size_t c = 0; c < candidates; ++c)
      if (in[c]) chosen.push_back(int(c));
  }
  return shrunk;
}

namespace {

// The state of the row-weighting search: which candidates are in, how often each sample is
// covered, the samples' weights, and each candidate's score (in: minus the weight it alone
// covers, the loss of dropping it; out: the weight of bare samples it covers, the gain of
// adding it).
class WeightedCover {
 public:
  WeightedCover(const Coverage& cov, const Coverage& by) : cov_(cov), by_(by) {
    const size_t n = cov.start.size() - 1, m = cov.sample_count;
    count_.assign(m, 0);
    weight_.assign(m, 1);
    bare_at_.assign(m, -1);
    score_.assign(n, 0);
    stamp_.assign(n, 0);
    in_.assign(n, 0);
    can_add_.assign(n, 1);
    for (uint32_t s = 0; s < m; ++s)
      if (by.row_size(s) > 0) make_bare(s);
    for (size_t c = 0; c < n; ++c)
      for (uint32_t k = cov.start[c]; k < cov.start[c + 1]; ++k) score_[c] += weight_[cov.samples[k]];
  }

  void add(uint32_t c, uint64_t step) {
    work_ += cov_.row_size(c);
    in_[c] = 1;
    score_[c] = -score_[c];
    stamp_[c] = step;
    members_.push_back(c);
    for (uint32_t k = cov_.start[c]; k < cov_.start[c + 1]; ++k) {
      const uint32_t s = cov_.samples[k];
      const uint32_t before = count_[s]++;
      if (before == 0) drop_bare(s);
      if (before > 1) continue;  // no score changes
      work_ += by_.row_size(s);
      for (uint32_t n = by_.start[s]; n < by_.start[s + 1]; ++n) {
        const uint32_t o = by_.samples[n];
        if (o == c) continue;
        can_add_[o] = 1;
        if (before == 0) score_[o] -= weight_[s];
        else if (in_[o]) score_[o] += weight_[s];
      }
    }
  }

  void remove(uint32_t c, uint64_t step) {
    work_ += cov_.row_size(c);
    in_[c] = 0;
    score_[c] = -score_[c];
    stamp_[c] = step;
    can_add_[c] = 0;
    members_.erase(std::find(members_.begin(), members_.end(), c));
    for (uint32_t k = cov_.start[c]; k < cov_.start[c + 1]; ++k) {
      const uint32_t s = cov_.samples[k];
      const uint32_t after = --count_[s];
      if (after == 0) make_bare(s);
      if (after > 1) continue;  // no score changes
      work_ += by_.row_size(s);
      for (uint32_t n = by_.start[s]; n < by_.start[s + 1]; ++n) {
        const uint32_t o = by_.samples[n];
        if (o == c) continue;
        can_add_[o] = 1;
        if (after == 0) score_[o] += weight_[s];
        else if (in_[o]) score_[o] -= weight_[s];
      }
    }
  }

  // Bare samples weigh one more, so the candidates covering them gain.
  void raise_bare_weights() {
    for (uint32_t s : bare_) {
      work_ += by_.row_size(s);
      ++weight_[s];
      for (uint32_t n = by_.start[s]; n < by_.start[s + 1]; ++n) ++score_[by_.samples[n]];
    }
  }

  // The member whose removal loses least (ties to the longest unchanged), other than `keep`.
  uint32_t cheapest_member(uint32_t keep) const {
    uint32_t best = UINT32_MAX;
    for (uint32_t c : members_)
      if (c != keep && (best == UINT32_MAX || better(c, best))) best = c;
    return best;
  }
  // The candidate covering sample s that gains most (ties to the longest unchanged), preferring
  // those whose neighbourhood changed since they were dropped (configuration checking).
  uint32_t best_adder(uint32_t s) const {
    uint32_t best = UINT32_MAX, fallback = UINT32_MAX;
    for (uint32_t n = by_.start[s]; n < by_.start[s + 1]; ++n) {
      const uint32_t c = by_.samples[n];
      if (fallback == UINT32_MAX || better(c, fallback)) fallback = c;
      if (can_add_[c] && (best == UINT32_MAX || better(c, best))) best = c;
    }
    return best == UINT32_MAX ? fallback : best;
  }
  bool covers_all() const { return bare_.empty(); }
  // Entries of the coverage visited so far: what the search has cost.
  uint64_t work() const { return work_; }
  size_t bare_count() const { return bare_.size(); }
  uint32_t bare(size_t i) const { return bare_[i]; }
  const std::vector<uint32_t>& members() const { return members_; }

 private:
  bool better(uint32_t a, uint32_t b) const {
    return score_[a] > score_[b] || (score_[a] == score_[b] && (stamp_[a] < stamp_[b] || (stamp_[a] == stamp_[b] && a < b)));
  }
  void make_bare(uint32_t s) {
    bare_at_[s] = int64_t(bare_.size());
    bare_.push_back(s);
  }
  void drop_bare(uint32_t s) {
    const int64_t at = bare_at_[s];
    bare_[size_t(at)] = bare_.back();
    bare_at_[bare_.back()] = at;
    bare_.pop_back();
    bare_at_[s] = -1;
  }

  const Coverage& cov_;
  const Coverage& by_;
  std::vector<uint32_t> count_;
  std::vector<int64_t> weight_, score_, bare_at_;
  std::vector<uint64_t> stamp_;
  std::vector<char> in_, can_add_;
  std::vector<uint32_t> bare_, members_;
  uint64_t work_ = 0;
};

}  // namespace

ReducedCover reduce_cover(const Coverage& cov, uint32_t scan) {
  const size_t candidates = cov.start.size() - 1;
  const Coverage by = covering_candidates(cov);
  auto is_subset = [](const uint32_t* a, const uint32_t* a_end, const uint32_t* b, const uint32_t* b_end) {
    if (a == a_end) return true;
    // Rows that are not subsets mostly differ at their ends or middle: test those first.
    if (*a < *b || *(a_end - 1) > *(b_end - 1) || !std::binary_search(b, b_end, a[(a_end - a) / 2])) return false;
    for (; a != a_end; ++a) {
      b = std::lower_bound(b, b_end, *a);
      if (b == b_end || *b != *a) return false;
    }
    return true;
  };
  // Samples: b is implied when some a's candidates are all among b's (a cover of a covers b).
  // Smallest first; a kept sample marks every larger one it implies (ties: the later index).
  std::vector<uint32_t> order;
  for (uint32_t s = 0; s < cov.sample_count; ++s)
    if (by.row_size(s) > 0) order.push_back(s);
  std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return by.row_size(a) < by.row_size(b); });
  // In parallel: which rows get marked does not depend on the order they are visited in (a
  // row implied by one that is itself implied is implied by that one's implier too). Rows whose
  // scan would pass `scan` imply nothing; that too depends on the row alone.
  std::vector<std::atomic<uint8_t>> implied(cov.sample_count);
  tbb::parallel_for(size_t(0), order.size(), [&](size_t k) {
    const uint32_t a = order[k];
    if (implied[a].load(std::memory_order_relaxed)) return;
    // Every sample implied by a is covered by a's candidate that covers fewest samples.
    uint32_t rare = by.samples[by.start[a]];
    for (uint32_t n = by.start[a]; n < by.start[a + 1]; ++n)
      if (cov.row_size(by.samples[n]) < cov.row_size(rare)) rare = by.samples[n];
    if (cov.row_size(rare) > scan) return;
    for (uint32_t n = cov.start[rare]; n < cov.start[rare + 1]; ++n) {
      const uint32_t b = cov.samples[n];
      if (b == a || implied[b].load(std::memory_order_relaxed) || by.row_size(b) < by.row_size(a)) continue;
      if (by.row_size(b) == by.row_size(a) && b < a) continue;  // identical rows: keep the earlier
      if (is_subset(&by.samples[by.start[a]], &by.samples[by.start[a + 1]], &by.samples[by.start[b]],
                    &by.samples[by.start[b + 1]]))
        implied[b].store(1, std::memory_order_relaxed);
    }
  });
  ReducedCover out;
  std::vector<uint32_t> row_of(cov.sample_count, UINT32_MAX);
  for (uint32_t s = 0; s < cov.sample_count; ++s)
    if (by.row_size(s) > 0 && !implied[s]) row_of[s] = uint32_t(out.sample.size()), out.sample.push_back(s);
  // Candidates over the kept samples; d is dominated when another covers all of its samples
  // (ties: the later index).
  std::vector<std::vector<uint32_t>> rows(candidates);
  for (size_t c = 0; c < candidates; ++c)
    for (uint32_t n = cov.start[c]; n < cov.start[c + 1]; ++n)
      if (row_of[cov.samples[n]] != UINT32_MAX) rows[c].push_back(row_of[cov.samples[n]]);
  std::vector<uint32_t> holders_start(out.sample.size() + 1, 0), holders;
  for (const auto& r : rows)
    for (uint32_t s : r) ++holders_start[s + 1];
  std::partial_sum(holders_start.begin(), holders_start.end(), holders_start.begin());
  holders.resize(holders_start.back());
  {
    std::vector<uint32_t> fill(holders_start.begin(), holders_start.end() - 1);
    for (size_t c = 0; c < candidates; ++c)
      for (uint32_t s : rows[c]) holders[fill[s]++] = uint32_t(c);
  }
  std::vector<std::atomic<uint8_t>> dominated(candidates);  // in parallel, as above
  tbb::parallel_for(size_t(0), candidates, [&](size_t d) {
    if (rows[d].empty()) {
      dominated[d].store(1, std::memory_order_relaxed);
      return;
    }
    uint32_t rare = rows[d].front();
    for (uint32_t s : rows[d])
      if (holders_start[s + 1] - holders_start[s] < holders_start[rare + 1] - holders_start[rare]) rare = s;
    if (holders_start[rare + 1] - holders_start[rare] > scan) return;
    for (uint32_t n = holders_start[rare]; n < holders_start[rare + 1]; ++n) {
      const uint32_t e = holders[n];
      if (e == d || dominated[e].load(std::memory_order_relaxed) || rows[e].size() < rows[d].size()) continue;
      if (rows[e].size() == rows[d].size() && e > d) continue;  // identical: keep the earlier
      if (is_subset(rows[d].data(), rows[d].data() + rows[d].size(), rows[e].data(), rows[e].data() + rows[e].size())) {
        dominated[d].store(1, std::memory_order_relaxed);
        break;
      }
    }
  });
  out.coverage.sample_count = out.sample.size();
  out.coverage.start.push_back(0);
  for (size_t c = 0; c < candidates; ++c) {
    if (dominated[c].load(std::memory_order_relaxed)) continue;
    out.candidate.push_back(uint32_t(c));
    out.coverage.samples.insert(out.coverage.samples.end(), rows[c].begin(), rows[c].end());
    out.coverage.start.push_back(uint32_t(out.coverage.samples.size()));
  }
  return out;
}

size_t local_search_cover(const Coverage& cov, std::vector<int>& chosen, SearchLimits limits, size_t enough,
                          uint64_t seed) {
  if (chosen.size() <= std::max<size_t>(1, enough) || limits.steps == 0) return 0;
  const Coverage by = covering_candidates(cov);
  WeightedCover state(cov, by);  // samples no candidate covers are never bare
  for (int c : chosen) state.add(uint32_t(c), 0);
  std::vector<int> best = chosen;
  SplitMix rng{seed};
  uint32_t tabu = UINT32_MAX;
  for (uint64_t step = 1; step <= limits.steps && best.size() > enough && state.work() < limits.work; ++step) {
    // A cover: keep it if smaller, then search one sphere below it.
    while (state.covers_all()) {
      if (state.members().size() < best.size()) best.assign(state.members().begin(), state.members().end());
      if (state.members().size() <= 1) break;
      state.remove(state.cheapest_member(UINT32_MAX), step);
    }
    if (state.members().size() <= 1) break;
    state.remove(state.cheapest_member(tabu), step);
    const uint32_t sample = state.bare(size_t(rng.next() % state.bare_count()));
    tabu = state.best_adder(sample);
    state.add(tabu, step);
    state.raise_bare_weights();
  }
  if (state.covers_all() && state.members().size() < best.size())
    best.assign(state.members().begin(), state.members().end());
  const size_t saved = chosen.size() - std::min(chosen.size(), best.size());
  if (best.size() < chosen.size()) {
    std::sort(best.begin(), best.end());
    chosen = best;
  }
  return saved;
}

namespace {

// The larger of the two lower bounds. On a reduced problem too: the reduction keeps the optimum
// of the problem and of its LP relaxation, so its bounds hold for the original.
// The Lagrangian's steps are capped at about 4e8 pairs visited in all (a dense budget cover's
// bound would otherwise cost more than its search).
size_t lower_bound_of(const Coverage& cov, size_t upper) {
  const int steps = int(std::clamp<size_t>(size_t(4e8) / std::max<size_t>(cov.samples.size(), 1), 20, 200));
  return std::max(cover_lower_bound(cov), lagrangian_bound(cov, upper, steps));
}

}  // namespace

std::vector<int> smallest_cover(const Coverage& cov, SearchLimits limits, size_t enough, size_t* lower_bound, Log& log) {
  const ReducedCover reduced = reduce_cover(cov, limits.scan);
  std::vector<int> chosen = greedy_cover(reduced.coverage);
  const size_t greedy = chosen.size();
  shrink_cover(reduced.coverage, chosen);
  const size_t shrunk = chosen.size();
  local_search_cover(reduced.coverage, chosen, limits, enough);
  std::string bound;
  if (lower_bound) {
    *lower_bound = lower_bound_of(reduced.coverage, chosen.size());
    bound = " (at least " + std::to_string(*lower_bound) + ")";
  }
  log.detail("cover of " + std::to_string(reduced.candidate.size()) + " candidates and " +
             std::to_string(reduced.sample.size()) + " samples after reduction: greedy " + std::to_string(greedy) +
             ", shrunk " + std::to_string(shrunk) + ", searched " + std::to_string(chosen.size()) + bound);
  for (int& c : chosen) c = int(reduced.candidate[size_t(c)]);
  std::sort(chosen.begin(), chosen.end());
  return chosen;
}

Coverage covering_candidates(const Coverage& cov) {
  const size_t candidates = cov.start.size() - 1;
  Coverage t;
  t.sample_count = candidates;
  t.start.assign(cov.sample_count + 1, 0);
  for (uint32_t s : cov.samples) ++t.start[s + 1];
  std::partial_sum(t.start.begin(), t.start.end(), t.start.begin());
  t.samples.resize(cov.samples.size());
  std::vector<uint32_t> fill(t.start.begin(), t.start.end() - 1);
  for (size_t c = 0; c < candidates; ++c)
    for (uint32_t n = cov.start[c]; n < cov.start[c + 1]; ++n) t.samples[fill[cov.samples[n]]++] = uint32_t(c);
  return t;
}

size_t cover_lower_bound(const Coverage& cov) {
  const size_t candidates = cov.start.size() - 1;
  const Coverage covering = covering_candidates(cov);
  const std::vector<uint32_t>& start = covering.start;
  const std::vector<uint32_t>& by = covering.samples;
  // Most constrained samples first; a pick blocks every sample a candidate of it covers.
  std::vector<uint32_t> order(cov.sample_count);
  std::iota(order.begin(), order.end(), 0u);
  std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) {
    return start[a + 1] - start[a] < start[b + 1] - start[b];
  });
  std::vector<char> blocked(cov.sample_count, 0), used(candidates, 0);
  size_t picked = 0;
  for (uint32_t s : order) {
    if (blocked[s] || start[s] == start[s + 1]) continue;
    ++picked;
    for (uint32_t n = start[s]; n < start[s + 1]; ++n) {
      const uint32_t c = by[n];
      if (used[c]) continue;
      used[c] = 1;
      for (uint32_t m = cov.start[c]; m < cov.start[c + 1]; ++m) blocked[cov.samples[m]] = 1;
    }
  }
  return picked;
}

size_t lagrangian_bound(const Coverage& cov, size_t upper, int steps) {
  const size_t candidates = cov.start.size() - 1, samples = cov.sample_count;
  std::vector<char> coverable(samples, 0);
  for (uint32_t s : cov.samples) coverable[s] = 1;
  // Start: each sample's multiplier the best 1/|column| among the candidates covering it.
  std::vector<double> u(samples, 0.0);
  for (size_t c = 0; c < candidates; ++c)
    for (uint32_t n = cov.start[c]; n < cov.start[c + 1]; ++n) {
      const double share = 1.0 / double(cov.row_size(c));
      if (u[cov.samples[n]] == 0 || share < u[cov.samples[n]]) u[cov.samples[n]] = share;
    }
  // Subgradient steps by Polyak's rule toward the best cover known (`upper`).
  std::vector<int> hits(samples, 0);
  double best = 0, lambda = 2.0;
  int since_better = 0;
  for (int step = 0; step < steps && lambda > 1e-3; ++step) {
    double value = 0;
    for (size_t s = 0; s < samples; ++s) value += u[s];
    std::fill(hits.begin(), hits.end(), 0);
    for (size_t c = 0; c < candidates; ++c) {
      if (cov.row_size(c) == 0) continue;
      double r = 1;
      for (uint32_t n = cov.start[c]; n < cov.start[c + 1]; ++n) r -= u[cov.samples[n]];
      if (r < 0) {
        value += r;
        for (uint32_t n = cov.start[c]; n < cov.start[c + 1]; ++n) ++hits[cov.samples[n]];
      }
    }
    if (value > best + 1e-9) {
      best = value;
      since_better = 0;
    } else if (++since_better >= 15) {
      lambda /= 2;
      since_better = 0;
    }
    if (std::ceil(best - 1e-6) >= double(upper)) break;  // the cover is optimal
    double norm = 0;
    for (size_t s = 0; s < samples; ++s)
      if (coverable[s]) {
        const double g = 1.0 - hits[s];
        if (g > 0 || u[s] > 0) norm += g * g;
      }
    if (norm == 0) break;
    const double t = lambda * (1.05 * double(upper) - value) / norm;
    for (size_t s = 0; s < samples; ++s)
      if (coverable[s]) u[s] = std::max(0.0, u[s] + t * (1.0 - hits[s]));
  }
  return size_t(std::max(0.0, std::ceil(best - 1e-6)));
}

namespace {

size_t uncovered_samples(const Coverage& cov) {
  std::vector<char> any(cov.sample_count, 0);
  for (uint32_t s : cov.samples) any[s] = 1;
  return size_t(std::count(any.begin(), any.end(), 0));
}

double largest_finite(const std::vector<double>& values) {
  double out = 0;
  for (double v : values)
    if (std::isfinite(v)) out = std::max(out, v);
  return out;
}

}  // namespace

CoverResult cover_within(const CoverProblem& problem, double delta, SearchLimits limits, Log& log) {
  CoverResult r;
  r.delta = delta;
  const Coverage cov = coverage_at(problem, delta);
  r.chosen = smallest_cover(cov, limits, 0, &r.lower_bound, log);
  improve_cover(problem, cov, delta, r.chosen.size(), r.chosen, log);
  r.uncoverable = uncovered_samples(cov);
  // Only a tolerance out of reach needs the least delta that would do (a full scan).
  r.least_reachable = r.uncoverable > 0 ? largest_finite(least_gaps(problem)) : delta;
  r.evaluations = 1;
  log.detail("cover at " + num(delta) + ": " + std::to_string(r.chosen.size()) + " spheres (at least " +
             std::to_string(r.lower_bound) + "), " + std::to_string(cov.samples.size()) + " pairs");
  return r;
}

CoverResult cover_for(const CoverProblem& problem, double target, size_t budget, std::string& limited_by, Log& log) {
  CoverResult cover;
  if (target > 0) {
    cover = cover_within(problem, target, kToleranceSearch, log);
    limited_by = cover.uncoverable > 0 ? "the field's resolution (some samples are out of reach)" : "met the tolerance";
  }
  if (budget > 0 && (!(target > 0) || cover.chosen.size() > budget)) {
    cover = cover_with_budget(problem, budget, kBudgetSlack, 1e-2, log);
    limited_by = target > 0 ? "max_spheres (tighter than the tolerance)" : "max_spheres";
  }
  return cover;
}

CoverResult cover_with_budget(const CoverProblem& problem, size_t max_spheres, double slack, double precision,
                              Log& log) {
  CoverResult best;
  const std::vector<double> gaps = least_gaps(problem);
  const double lo_start = largest_finite(gaps);
  best.least_reachable = lo_start;
  // Each table holds the pairs up to (1 + slack) times its delta: the relaxed cover at the end
  // comes from the same table.
  const double reach = 1 + std::max(slack, 0.0);
  std::unique_ptr<GapTable> table;
  auto solve = [&](double delta) {
    Coverage v = table->at(delta);
    ++best.evaluations;
    return std::make_pair(greedy_cover(v), std::move(v));
  };
  // Below the largest least gap some sample cannot be covered; above it, grow until it fits.
  double lo = lo_start, hi = std::max(lo_start, 1e-12) * 1.25;
  table = std::make_unique<GapTable>(problem, hi * reach);
  auto [cover, cov] = solve(hi);
  while (cover.size() > max_spheres && best.evaluations < 60) {
    lo = hi;
    hi *= 2;
    table = std::make_unique<GapTable>(problem, hi * reach);
    std::tie(cover, cov) = solve(hi);
  }
  best.chosen = cover;
  best.delta = hi;
  Coverage best_cov = std::move(cov);
  while (hi - lo > precision * hi && best.evaluations < 60) {
    const double mid = 0.5 * (lo + hi);
    auto [c, v] = solve(mid);
    if (c.size() <= max_spheres) {
      hi = mid;
      best.chosen = std::move(c);
      best.delta = mid;
      best_cov = std::move(v);
    } else {
      lo = mid;
    }
  }
  // The row-weighting search fits the budget at a smaller delta than greedy does: bisect
  // below greedy's delta, each cover searched until it fits.
  lo = std::max(lo_start, (1 - kSearchReach) * best.delta);
  for (int step = 0; step < kSearchBisections && best.delta - lo > precision * best.delta; ++step) {
    const double mid = 0.5 * (lo + best.delta);
    Coverage v = table->at(mid);
    ++best.evaluations;
    std::vector<int> c = smallest_cover(v, kBudgetSearch, max_spheres, nullptr, log);
    if (c.size() <= max_spheres) {
      best.chosen = std::move(c);
      best.delta = mid;
      best_cov = std::move(v);
    } else {
      lo = mid;
    }
  }
  best.least_max_delta = best.delta;
  if (slack > 0) {
    // A little more max error buys a lower median: the cover at the relaxed delta is smaller,
    // and improve_cover spends the budget it leaves on the total error.
    Coverage v = table->at(best.delta * (1 + slack));
    ++best.evaluations;
    std::vector<int> c = smallest_cover(v, kBudgetSearch, 0, nullptr);
    if (c.size() <= max_spheres) {
      best.delta *= 1 + slack;
      best.chosen = std::move(c);
      best_cov = std::move(v);
    }
  }
  if (best.chosen.size() > max_spheres) best.chosen.resize(max_spheres);  // never over budget
  improve_cover(problem, best_cov, best.delta, max_spheres, best.chosen, log);
  best.lower_bound = lower_bound_of(best_cov, best.chosen.size());
  best.uncoverable = uncovered_samples(best_cov);
  log.detail("budget " + std::to_string(max_spheres) + ": delta " + num(best.delta) + " with " +
             std::to_string(best.chosen.size()) + " spheres after " + std::to_string(best.evaluations) + " covers");
  return best;
}

namespace {

// Gaps between samples (stacked over poses) and candidates, and each sample's two nearest
// chosen spheres among those that cover it at delta.
class CoverState {
 public:
  CoverState(const CoverProblem& problem, const Coverage& cov, double delta)
      : problem_(problem), cov_(cov), delta_(delta) {
    for (size_t k = 0; k < problem.samples.size(); ++k)
      for (size_t i = 0; i < problem.samples[k].size(); ++i) {
        where_.emplace_back(uint32_t(k), uint32_t(i));
        weight_.push_back(problem.weighted.empty() || i < problem.weighted[k] ? 1.0 : 0.0);
      }
    const Coverage covering = covering_candidates(cov);
    by_start_ = covering.start;
    by_ = covering.samples;
    in_.assign(cov.start.size() - 1, 0);
    first_.assign(cov.sample_count, -1);
    second_.assign(cov.sample_count, -1);
  }

  double weight(uint32_t s) const { return weight_[s]; }
  // Infinite for a sphere of radius 0: it is absent from that pose and covers nothing there,
  // however near its center (as in the coverage rows).
  double gap(uint32_t s, int c) const {
    const auto [k, i] = where_[s];
    const Sphere& sphere = problem_.spheres[k][size_t(c)];
    if (!(sphere.radius > 0)) return std::numeric_limits<double>::infinity();
    return (problem_.samples[k][i] - sphere.center).norm() - sphere.radius;
  }
  // The sample's error with the chosen set: its gap to the nearest chosen sphere covering it
  // (delta's worth past delta where none does: such a sample only arises from uncoverable ones).
  double error(uint32_t s) const { return first_[s] < 0 ? 2 * delta_ : gap(s, first_[s]); }
  double error_without(uint32_t s, int c) const {
    const int best = first_[s] == c ? second_[s] : first_[s];
    return best < 0 ? 2 * delta_ : gap(s, best);
  }

  void set(const std::vector<int>& chosen) {
    std::fill(in_.begin(), in_.end(), 0);
    for (int c : chosen) in_[size_t(c)] = 1;
    for (uint32_t s = 0; s < cov_.sample_count; ++s) update(s);
  }
  void swap(int out, int in) {
    in_[size_t(out)] = 0;
    in_[size_t(in)] = 1;
    for (int c : {out, in})
      for (uint32_t n = cov_.start[size_t(c)]; n < cov_.start[size_t(c) + 1]; ++n) update(cov_.samples[n]);
  }
  void add(int c) {
    in_[size_t(c)] = 1;
    for (uint32_t n = cov_.start[size_t(c)]; n < cov_.start[size_t(c) + 1]; ++n) update(cov_.samples[n]);
  }
  bool chosen(int c) const { return in_[size_t(c)] != 0; }
  int first(uint32_t s) const { return first_[s]; }
  int second(uint32_t s) const { return second_[s]; }
  const uint32_t* covering_begin(uint32_t s) const { return by_.data() + by_start_[s]; }
  const uint32_t* covering_end(uint32_t s) const { return by_.data() + by_start_[s + 1]; }

 private:
  void update(uint32_t s) {
    int a = -1, b = -1;
    double ga = 0, gb = 0;
    for (uint32_t n = by_start_[s]; n < by_start_[s + 1]; ++n) {
      const int c = int(by_[n]);
      if (!in_[size_t(c)]) continue;
      const double g = gap(s, c);
      if (a < 0 || g < ga) {
        b = a, gb = ga;
        a = c, ga = g;
      } else if (b < 0 || g < gb) {
        b = c, gb = g;
      }
    }
    first_[s] = a;
    second_[s] = b;
  }

  const CoverProblem& problem_;
  const Coverage& cov_;
  double delta_;
  std::vector<std::pair<uint32_t, uint32_t>> where_;  // sample -> (pose, index)
  std::vector<double> weight_;
  std::vector<uint32_t> by_start_, by_;
  std::vector<char> in_;
  std::vector<int> first_, second_;
};

}  // namespace

void improve_cover(const CoverProblem& problem, const Coverage& cov, double delta, size_t max_spheres,
                   std::vector<int>& chosen, Log& log) {
  if (chosen.empty()) return;
  CoverState state(problem, cov, delta);
  state.set(chosen);
  const size_t candidates = cov.start.size() - 1;
  // Spare budget: the candidate that cuts the total error most, while one does.
  size_t added = 0;
  while (chosen.size() < max_spheres) {
    std::vector<double> cut(candidates, 0);
    tbb::parallel_for(size_t(0), candidates, [&](size_t c) {
      if (state.chosen(int(c))) return;
      double sum = 0;
      for (uint32_t n = cov.start[c]; n < cov.start[c + 1]; ++n)
        sum += state.weight(cov.samples[n]) * std::max(0.0, state.error(cov.samples[n]) - state.gap(cov.samples[n], int(c)));
      cut[c] = sum;
    });
    const size_t best = size_t(std::max_element(cut.begin(), cut.end()) - cut.begin());
    if (!(cut[best] > 0)) break;
    state.add(int(best));
    chosen.push_back(int(best));
    ++added;
  }
  // Swaps: a sphere for one that covers every sample only it covers, cutting the sum most.
  size_t swaps = 0;
  for (int round = 0; round < 4; ++round) {
    size_t this_round = 0;
    for (size_t slot = 0; slot < chosen.size(); ++slot) {
      const int out = chosen[slot];
      // Samples only `out` covers: a replacement must cover them all.
      std::vector<uint32_t> critical;
      for (uint32_t n = cov.start[size_t(out)]; n < cov.start[size_t(out) + 1]; ++n) {
        const uint32_t s = cov.samples[n];
        if (state.first(s) == out && state.second(s) < 0) critical.push_back(s);
      }
      // Candidates: those covering the first critical sample (every sample of `out` if none).
      const uint32_t anchor = critical.empty() ? cov.samples[cov.start[size_t(out)]] : critical.front();
      std::vector<int> options;
      for (const uint32_t* c = state.covering_begin(anchor); c != state.covering_end(anchor); ++c)
        if (!state.chosen(int(*c))) options.push_back(int(*c));
      std::vector<double> change(options.size(), std::numeric_limits<double>::infinity());
      tbb::parallel_for(size_t(0), options.size(), [&](size_t o) {
        const int in = options[o];
        for (uint32_t s : critical)
          if (state.gap(s, in) > delta) return;
        double sum = 0;
        // Samples losing `out` fall back to their second sphere or to `in`.
        for (uint32_t n = cov.start[size_t(out)]; n < cov.start[size_t(out) + 1]; ++n) {
          const uint32_t s = cov.samples[n];
          if (state.first(s) != out) continue;
          const double g = state.gap(s, in);
          sum += state.weight(s) *
                 (std::min(state.error_without(s, out), g <= delta ? g : std::numeric_limits<double>::infinity()) -
                  state.error(s));
        }
        // Samples `in` brings closer (those whose nearest is `out` are counted above).
        for (uint32_t n = cov.start[size_t(in)]; n < cov.start[size_t(in) + 1]; ++n) {
          const uint32_t s = cov.samples[n];
          if (state.first(s) == out) continue;
          sum += state.weight(s) * std::min(0.0, state.gap(s, in) - state.error(s));
        }
        change[o] = sum;
      });
      size_t best = options.size();
      for (size_t o = 0; o < options.size(); ++o)
        if (change[o] < -1e-12 * delta && (best == options.size() || change[o] < change[best])) best = o;
      if (best == options.size()) continue;
      state.swap(out, options[best]);
      chosen[slot] = options[best];
      ++this_round;
    }
    swaps += this_round;
    if (this_round == 0) break;
  }
  log.detail("cover improved: " + std::to_string(added) + " spheres added, " + std::to_string(swaps) + " swaps");
}

size_t refine_centers(const std::vector<Eigen::Vector3d>& samples, size_t weighted, SphereSet& spheres,
                      const std::function<double(const Eigen::Vector3d&)>& radius_at, double delta, double step,
                      Log& log) {
  if (spheres.empty() || samples.empty()) return 0;
  const SampleGrid grid(samples);
  // Each sample's nearest and second-nearest sphere.
  std::vector<int> first(samples.size(), -1), second(samples.size(), -1);
  auto gap = [&](size_t i, const Sphere& s) { return (samples[i] - s.center).norm() - s.radius; };
  auto rank = [&](size_t i) {
    int a = -1, b = -1;
    double ga = 0, gb = 0;
    for (size_t j = 0; j < spheres.size(); ++j) {
      const double g = gap(i, spheres[j]);
      if (a < 0 || g < ga) {
        b = a, gb = ga;
        a = int(j), ga = g;
      } else if (b < 0 || g < gb) {
        b = int(j), gb = g;
      }
    }
    first[i] = a;
    second[i] = b;
  };
  tbb::parallel_for(size_t(0), samples.size(), [&](size_t i) { rank(i); });
  auto error_without = [&](size_t i, size_t j) {
    const int k = first[i] == int(j) ? second[i] : first[i];
    return k < 0 ? std::numeric_limits<double>::infinity() : gap(i, spheres[size_t(k)]);
  };
  size_t moves = 0;
  for (double s = step; s >= step / 4; s /= 2)
    for (int round = 0; round < 3; ++round) {
      size_t this_round = 0;
      for (size_t j = 0; j < spheres.size(); ++j) {
        const Sphere old = spheres[j];
        Sphere best_sphere = old;
        double best_change = -1e-12 * delta;
        for (int d = 0; d < 6; ++d) {
          Eigen::Vector3d c = old.center;
          c[d / 2] += d % 2 ? s : -s;
          const double r = radius_at(c);
          if (!(r > 0)) continue;
          const Sphere moved{c, r};
          // Samples whose error can change: near the old sphere or the new one.
          double change = 0;
          bool feasible = true;
          auto visit = [&](uint32_t i) {
            if (!feasible) return;
            const double before = gap(i, spheres[size_t(first[i])]);
            const double after = std::min(error_without(i, j), gap(i, moved));
            if (after > delta && after > before) feasible = false;
            if (i < weighted) change += after - before;
          };
          std::vector<uint32_t> seen;
          grid.near(old.center, old.radius + delta, [&](uint32_t i) { seen.push_back(i); });
          grid.near(c, r + delta, [&](uint32_t i) { seen.push_back(i); });
          std::sort(seen.begin(), seen.end());
          seen.erase(std::unique(seen.begin(), seen.end()), seen.end());
          for (uint32_t i : seen) visit(i);
          if (feasible && change < best_change) {
            best_change = change;
            best_sphere = moved;
          }
        }
        if (best_sphere.center == old.center) continue;
        spheres[j] = best_sphere;
        ++this_round;
        std::vector<uint32_t> seen;
        grid.near(old.center, old.radius + delta, [&](uint32_t i) { seen.push_back(i); });
        grid.near(best_sphere.center, best_sphere.radius + delta, [&](uint32_t i) { seen.push_back(i); });
        for (uint32_t i : seen) rank(i);
      }
      moves += this_round;
      if (this_round == 0) break;
    }
  log.detail("refined centers: " + std::to_string(moves) + " moves");
  return moves;
}

}  // namespace spx
