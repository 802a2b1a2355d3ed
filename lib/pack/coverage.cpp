#include "pack/coverage.hpp"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <memory>

#include "mesh/union_distance.hpp"
#include "pack/sample_grid.hpp"

namespace spx {
using detail::SampleGrid;

size_t CoverProblem::sample_count() const {
  size_t n = 0;
  for (const auto& s : samples) n += s.size();
  return n;
}

namespace {

// A point's gap to a sphere, from their squared distance (as norm() computes it): one home, so
// that a gap table's tie, decided again from the geometry, has the bits its pair was kept by.
double gap_from(double squared, const Sphere& s) { return std::sqrt(squared) - s.radius; }

// The coverage rule, in one place: visit(i, gap) for every point of `grid` (built on `points`)
// that sphere `s` covers at delta (gap = |p - c| - r <= delta); a sphere of radius 0 covers none.
// `skip`, where given: points i with skip[i] set are not visited.
template <class Visit>
void for_each_covered(const SampleGrid& grid, const std::vector<Eigen::Vector3d>& points, const Sphere& s, double delta,
                      Visit&& visit, const char* skip = nullptr) {
  if (!(s.radius > 0)) return;
  const double reach = s.radius + delta;
  // Past this squared distance a point is surely farther than reach, whatever the rounding of
  // the gap below: no square root for the grid's points outside the ball (about half of them).
  const double beyond = reach * reach * (1 + 1e-9);
  grid.near(s.center, reach, [&](uint32_t i) {
    if (skip && skip[i]) return;
    const double squared = (points[i] - s.center).squaredNorm();
    if (squared > beyond) return;
    const double gap = gap_from(squared, s);
    if (gap <= delta) visit(i, gap);
  });
}

// Candidates per chunk of gather_rows: a chunk's rows are gathered into one buffer per thread
// and stored at their exact size, so that no row grows on its own (a reallocation and fresh
// pages per row) and the rows are never held twice.
constexpr size_t kRowChunk = 256;

// A row's entry: its sample in the high bits and, in a gap table, the gap's bucket in the low
// `shift` bits (0 in a coverage row: the entry is the sample).
uint32_t sample_of(uint32_t entry, uint32_t shift) { return entry >> shift; }

// Entries of distinct samples in [from, to) put in sample order. Many of them (a large sphere
// at a large delta) are laid out by a bitmap of the range, a pass over its words in place of a
// sort's comparisons; few are sorted. Either way the same order.
class RowSorter {
 public:
  using Entry = uint32_t;
  void sort(Entry* begin, Entry* end, uint32_t from, uint32_t to, uint32_t shift) {
    const size_t n = size_t(end - begin), words = (size_t(to - from) + 63) / 64;
    if (n * kEntriesPerWord < words) {
      std::sort(begin, end);  // distinct samples in the high bits: the entries' order is theirs
      return;
    }
    if (bits_.size() < words) bits_.resize(words, 0);
    if (slot_.size() < size_t(to - from)) slot_.resize(size_t(to - from));
    size_t low = words, high = 0;
    for (const Entry* e = begin; e != end; ++e) {
      const uint32_t i = sample_of(*e, shift) - from;
      bits_[i >> 6] |= uint64_t(1) << (i & 63);
      slot_[i] = *e;
      low = std::min(low, size_t(i >> 6));
      high = std::max(high, size_t(i >> 6));
    }
    Entry* out = begin;
    for (size_t w = low; w <= high && n > 0; ++w) {
      for (uint64_t b = bits_[w]; b; b &= b - 1) *out++ = slot_[w * 64 + size_t(__builtin_ctzll(b))];
      bits_[w] = 0;
    }
  }

 private:
  // A sort costs each entry about what the pass costs for 16 words of the bitmap.
  static constexpr size_t kEntriesPerWord = 16;
  std::vector<uint64_t> bits_;
  std::vector<Entry> slot_;
};

// Every (candidate, sample) pair within `delta`, in chunks of kRowChunk candidates side by side:
// `entry(sample, gap)` is its entry (the sample above `shift` bits), each row sorted by sample,
// then `store(chunk, ends, entries)` takes the chunk (`ends`: one past each of its rows).
template <class MakeEntry, class Store>
void gather_rows(const CoverProblem& problem, double delta, std::vector<uint32_t>& offset, uint32_t shift,
                 MakeEntry&& entry, Store&& store) {
  using Entry = RowSorter::Entry;
  const size_t candidates = problem.candidate_count();
  std::vector<SampleGrid> grids;
  offset.assign(1, 0);
  for (const auto& s : problem.samples) {
    grids.emplace_back(s);
    offset.push_back(offset.back() + uint32_t(s.size()));
  }
  const std::vector<char> active =
      problem.merge > 0 ? representatives(problem, problem.merge * delta) : std::vector<char>(candidates, 1);
  tbb::enumerable_thread_specific<std::vector<Entry>> buffers;
  tbb::enumerable_thread_specific<RowSorter> sorters;
  tbb::parallel_for(size_t(0), (candidates + kRowChunk - 1) / kRowChunk, [&](size_t chunk) {
    std::vector<Entry>& entries = buffers.local();
    RowSorter& sorter = sorters.local();
    entries.clear();
    std::vector<uint32_t> ends;
    const size_t first = chunk * kRowChunk, last = std::min(candidates, first + kRowChunk);
    for (size_t c = first; c < last; ++c) {
      for (size_t k = 0; k < problem.samples.size() && active[c]; ++k) {
        // A pose's part of the row: its samples come after the poses' before it.
        const size_t begin = entries.size();
        for_each_covered(grids[k], problem.samples[k], problem.spheres[k][c], delta,
                         [&](uint32_t i, double gap) { entries.push_back(entry(offset[k] + i, gap)); });
        sorter.sort(entries.data() + begin, entries.data() + entries.size(), offset[k], offset[k + 1], shift);
      }
      ends.push_back(uint32_t(entries.size()));
    }
    store(chunk, ends, entries);
  });
}

}  // namespace

std::vector<char> representatives(const CoverProblem& problem, double slack) {
  const size_t n = problem.candidate_count();
  std::vector<char> kept(n, 1);
  if (n == 0) return kept;
  const SphereSet& first = problem.spheres[0];
  std::vector<uint32_t> order(n);
  std::vector<Eigen::Vector3d> centres(n);
  for (size_t c = 0; c < n; ++c) {
    order[c] = uint32_t(c);
    centres[c] = first[c].center;
  }
  std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return first[a].radius > first[b].radius; });
  const SampleGrid grid(centres);
  auto contains = [&](uint32_t big, uint32_t small) {
    if (!(first[small].radius > 0)) return false;  // found by its pose-0 centre: absent there, kept
    for (const SphereSet& pose : problem.spheres) {
      const Sphere &a = pose[small], &b = pose[big];
      if (!(a.radius > 0)) continue;
      if (!(b.radius > 0) || (a.center - b.center).norm() + a.radius - b.radius > slack) return false;
    }
    return true;
  };
  // Each kept sphere (largest first) leaves out the smaller ones it nearly contains: those lie
  // within its radius and the slack. A block of the order at a time: what each of its spheres
  // kept so far contains is found side by side, then left out in order by those still kept.
  std::vector<uint32_t> rank(n);
  for (size_t k = 0; k < n; ++k) rank[order[k]] = uint32_t(k);
  constexpr size_t kBlock = 1024;
  std::vector<std::vector<uint32_t>> inside(kBlock);
  for (size_t from = 0; from < n; from += kBlock) {
    const size_t to = std::min(n, from + kBlock);
    tbb::parallel_for(size_t(from), to, [&](size_t k) {
      const uint32_t b = order[k];
      std::vector<uint32_t>& out = inside[k - from];
      out.clear();
      if (!kept[b]) return;
      grid.near(centres[b], first[b].radius + slack, [&](uint32_t a) {
        if (rank[a] > rank[b] && kept[a] && contains(b, a)) out.push_back(a);
      });
    });
    for (size_t k = from; k < to; ++k)
      if (kept[order[k]])
        for (uint32_t a : inside[k - from]) kept[a] = 0;
  }
  return kept;
}

Coverage coverage_at(const CoverProblem& problem, double delta) {
  const size_t candidates = problem.candidate_count();
  std::vector<uint32_t> offset;
  std::vector<std::vector<uint32_t>> chunks((candidates + kRowChunk - 1) / kRowChunk);
  std::vector<uint32_t> size(candidates);
  gather_rows(
      problem, delta, offset, 0, [](uint32_t sample, double) { return sample; },
      [&](size_t chunk, const std::vector<uint32_t>& ends, const std::vector<uint32_t>& entries) {
        for (size_t n = 0; n < ends.size(); ++n) size[chunk * kRowChunk + n] = ends[n] - (n > 0 ? ends[n - 1] : 0);
        chunks[chunk].assign(entries.begin(), entries.end());
      });
  Coverage cov;
  cov.sample_count = offset.back();
  cov.start.assign(candidates + 1, 0);
  for (size_t c = 0; c < candidates; ++c) cov.start[c + 1] = cov.start[c] + size[c];
  cov.samples.resize(cov.start.back());
  tbb::parallel_for(size_t(0), chunks.size(), [&](size_t k) {
    std::copy(chunks[k].begin(), chunks[k].end(), cov.samples.begin() + cov.start[k * kRowChunk]);
    std::vector<uint32_t>().swap(chunks[k]);
  });
  return cov;
}

Coverage CoverageCache::coverage(const std::vector<std::vector<Eigen::Vector3d>>& samples, size_t count,
                                 const SphereOf& sphere, const std::vector<std::pair<size_t, std::vector<uint32_t>>>& parts) {
  const uint32_t candidates = uint32_t(count);
  // Each stacked sample's column, kept from the last problem where it was there.
  std::map<std::pair<size_t, uint32_t>, Column> kept;
  std::vector<Column*> column;
  std::vector<uint32_t> offset(1, 0);
  for (const auto& [source, indices] : parts) {
    for (uint32_t i : indices) {
      const std::pair<size_t, uint32_t> name{source, i};
      const auto [at, fresh] = kept.try_emplace(name);
      if (fresh) {
        const auto old = columns_.find(name);
        if (old != columns_.end()) at->second = std::move(old->second);
      }
      column.push_back(&at->second);
    }
    offset.push_back(uint32_t(column.size()));
  }
  columns_.swap(kept);  // the samples that left are forgotten
  complete(samples, candidates, sphere, offset, column);
  // The columns as rows over the stacked samples (each row ascending).
  return transposed(column.size(), candidates, [&](size_t n) -> const std::vector<uint32_t>& { return column[n]->covering; });
}

std::vector<std::vector<uint32_t>> CoverageCache::uncovered_joining(
    const std::vector<std::vector<Eigen::Vector3d>>& samples, size_t count, const SphereOf& sphere,
    const std::vector<std::pair<size_t, std::vector<uint32_t>>>& parts) {
  std::vector<Column*> column;
  std::vector<uint32_t> offset(1, 0);
  for (const auto& [source, indices] : parts) {
    for (uint32_t i : indices) column.push_back(&columns_[{source, i}]);
    offset.push_back(uint32_t(column.size()));
  }
  complete(samples, uint32_t(count), sphere, offset, column);
  std::vector<std::vector<uint32_t>> out(parts.size());
  for (size_t k = 0; k < parts.size(); ++k)
    for (uint32_t n = offset[k]; n < offset[k + 1]; ++n)
      if (column[n]->covering.empty()) out[k].push_back(n - offset[k]);
  return out;
}

void CoverageCache::complete(const std::vector<std::vector<Eigen::Vector3d>>& samples, uint32_t candidates,
                             const SphereOf& sphere, const std::vector<uint32_t>& offset,
                             const std::vector<Column*>& column) const {
  // By first candidate unchecked: the stacked samples still to check against the rest. Each is
  // marked checked as it is listed, so that a sample named twice is checked once.
  std::map<uint32_t, std::vector<uint32_t>> unchecked;
  for (uint32_t n = 0; n < column.size(); ++n)
    if (column[n]->upto < candidates) {
      unchecked[column[n]->upto].push_back(n);
      column[n]->upto = candidates;
    }
  for (const auto& [from, stacked] : unchecked) check(samples, candidates, sphere, offset, stacked, from, column);
}

void CoverageCache::check(const std::vector<std::vector<Eigen::Vector3d>>& samples, uint32_t candidates,
                          const SphereOf& sphere, const std::vector<uint32_t>& offset, const std::vector<uint32_t>& stacked,
                          uint32_t from, const std::vector<Column*>& column) const {
  // The samples' points by part, then every candidate from `from` on against them, as
  // gather_rows does.
  std::vector<size_t> part;
  std::vector<std::vector<uint32_t>> which;  // stacked indices, per part
  for (uint32_t n : stacked) {
    const size_t k = size_t(std::upper_bound(offset.begin(), offset.end(), n) - offset.begin()) - 1;
    if (part.empty() || part.back() != k) part.push_back(k), which.emplace_back();
    which.back().push_back(n);
  }
  std::vector<std::vector<Eigen::Vector3d>> points(part.size());
  std::vector<SampleGrid> grids;
  for (size_t g = 0; g < part.size(); ++g) {
    for (uint32_t n : which[g]) points[g].push_back(samples[part[g]][n - offset[part[g]]]);
    grids.emplace_back(points[g]);
  }
  // A block of candidates at a time, so that their rows are never all held beside the columns.
  constexpr uint32_t kBlock = 4096;
  std::vector<std::vector<uint32_t>> rows(kBlock);
  for (uint32_t first = from; first < candidates; first += kBlock) {
    const uint32_t end = std::min(candidates, first + kBlock);
    // Part by part, so that one part's grid and its candidates' spheres are read together; each
    // row still lists its samples part by part.
    for (size_t g = 0; g < part.size(); ++g)
      tbb::parallel_for(tbb::blocked_range<size_t>(first, end, 64), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t c = r.begin(); c != r.end(); ++c)
          for_each_covered(grids[g], points[g], sphere(part[g], c), delta_,
                           [&](uint32_t n, double) { rows[c - first].push_back(which[g][n]); });
      });
    // Candidates in ascending order: each column stays sorted.
    for (uint32_t c = first; c < end; ++c) {
      for (uint32_t n : rows[c - first]) column[n]->covering.push_back(c);
      rows[c - first].clear();
    }
  }
  for (uint32_t n : stacked) {
    column[n]->upto = candidates;
    column[n]->covering.shrink_to_fit();  // kept for rounds: no room left over from growing
  }
}

GapTable::GapTable(const CoverProblem& problem, double max_delta) : problem_(problem), max_delta_(max_delta) {
  // The samples' indices take the high bits they need, the buckets the rest: 16 and more bits
  // (65 536 buckets) up to 65 536 samples, 12 at a million.
  const uint32_t largest = uint32_t(std::max<size_t>(problem.sample_count(), 2) - 1);
  shift_ = uint32_t(std::min(31, __builtin_clz(largest)));
  top_ = double((uint32_t(1) << shift_) - 1);
  scale_ = max_delta > 0 ? top_ / max_delta : 0;
  chunks_.resize((problem.candidate_count() + kRowChunk - 1) / kRowChunk);
  gather_rows(
      problem, max_delta, offset_, shift_, [&](uint32_t sample, double gap) { return sample << shift_ | bucket(gap); },
      [&](size_t k, const std::vector<uint32_t>& ends, const std::vector<uint32_t>& entries) {
        chunks_[k].ends = ends;
        chunks_[k].entries.assign(entries.begin(), entries.end());
      });
  candidates_ = problem.candidate_count();
}

uint32_t GapTable::bucket(double gap) const { return gap > 0 ? uint32_t(std::min(top_, std::floor(gap * scale_))) : 0; }

bool GapTable::within(size_t candidate, uint32_t sample, double delta) const {
  const size_t k = size_t(std::upper_bound(offset_.begin(), offset_.end(), sample) - offset_.begin()) - 1;
  const Sphere& s = problem_.spheres[k][candidate];
  return gap_from((problem_.samples[k][sample - offset_[k]] - s.center).squaredNorm(), s) <= delta;
}

void GapTable::shrink(double max_delta) {
  if (!(max_delta < max_delta_)) return;
  // A pair in max_delta's own bucket may lie past it, and stays: at() asks the geometry there.
  const uint32_t edge = bucket(max_delta), mask = (uint32_t(1) << shift_) - 1;
  tbb::parallel_for(size_t(0), chunks_.size(), [&](size_t k) {
    Chunk& chunk = chunks_[k];
    uint32_t out = 0;
    for (uint32_t n = 0, c = 0; c < chunk.ends.size(); ++c) {
      for (; n < chunk.ends[c]; ++n)
        if ((chunk.entries[n] & mask) <= edge) chunk.entries[out++] = chunk.entries[n];
      chunk.ends[c] = out;
    }
    chunk.entries.resize(out);
    chunk.entries.shrink_to_fit();
  });
  max_delta_ = max_delta;
}

Coverage GapTable::at(double delta) const {
  delta = std::min(delta, max_delta_);
  const uint32_t edge = bucket(delta), mask = (uint32_t(1) << shift_) - 1;
  // Each chunk's rows filtered side by side (into room for all its entries), then laid end to end.
  std::vector<std::unique_ptr<uint32_t[]>> kept(chunks_.size());
  std::vector<uint32_t> size(candidates_);
  tbb::parallel_for(size_t(0), chunks_.size(), [&](size_t k) {
    const Chunk& chunk = chunks_[k];
    kept[k].reset(new uint32_t[chunk.entries.size()]);
    uint32_t* out = kept[k].get();
    for (uint32_t n = 0, c = 0; c < chunk.ends.size(); ++c) {
      const uint32_t* before = out;
      for (; n < chunk.ends[c]; ++n) {
        const uint32_t e = chunk.entries[n], b = e & mask;
        if (b < edge || (b == edge && within(k * kRowChunk + c, sample_of(e, shift_), delta))) *out++ = sample_of(e, shift_);
      }
      size[k * kRowChunk + c] = uint32_t(out - before);
    }
  });
  Coverage cov;
  cov.sample_count = offset_.back();
  cov.start.assign(candidates_ + 1, 0);
  for (size_t c = 0; c < candidates_; ++c) cov.start[c + 1] = cov.start[c] + size[c];
  cov.samples.resize(cov.start.back());
  tbb::parallel_for(size_t(0), kept.size(), [&](size_t k) {
    const size_t first = k * kRowChunk, last = std::min(candidates_, first + kRowChunk);
    std::copy(kept[k].get(), kept[k].get() + (cov.start[last] - cov.start[first]), cov.samples.begin() + cov.start[first]);
    kept[k].reset();
  });
  return cov;
}

double largest_gap_to(const CoverProblem& problem, size_t first, size_t count) {
  double out = 0;
  for (size_t p = 0; p < problem.samples.size(); ++p) {
    const auto from = problem.spheres[p].begin() + long(first);
    for (double gap : union_signed_distance(problem.samples[p], SphereSet(from, from + long(count))))
      out = std::max(out, gap);
  }
  return out;
}

std::vector<uint32_t> bare_samples(const std::vector<Eigen::Vector3d>& samples, const SphereSet& spheres, double delta) {
  std::vector<uint32_t> out;
  if (samples.empty()) return out;
  const SampleGrid grid(samples);
  std::vector<char> covered(samples.size(), 0);
  // A sample already covered is passed over before its distance is taken: where spheres overlap,
  // most of those a ball reaches are.
  for (const Sphere& s : spheres)
    for_each_covered(grid, samples, s, delta, [&](uint32_t i, double) { covered[i] = 1; }, covered.data());
  for (size_t i = 0; i < samples.size(); ++i)
    if (!covered[i]) out.push_back(uint32_t(i));
  return out;
}

// A sphere of radius 0 in a pose only costs the host there. Candidates that are 0 in half the
// poses or more are not offered: every pose of theirs is set to 0, so they cover nothing.
// Returns how many of candidates [from..] were.
size_t withdraw_mostly_absent(CoverProblem& problem, size_t from) {
  const size_t poses = problem.spheres.size(), candidates = problem.candidate_count();
  size_t dropped = 0;
  for (size_t c = from; c < candidates; ++c) {
    size_t absent = 0;
    for (size_t k = 0; k < poses; ++k) absent += !(problem.spheres[k][c].radius > 0);
    if (absent == 0 || 2 * absent < poses) continue;
    for (size_t k = 0; k < poses; ++k) problem.spheres[k][c].radius = 0;
    dropped += absent < poses;  // those 0 everywhere were never on offer
  }
  return dropped;
}

}  // namespace spx
