#include "pack/set_cover.hpp"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <limits>
#include <numeric>
#include <queue>

namespace spx {

namespace {

// How many candidates cover each sample: per chunk of rows side by side, then summed.
std::vector<uint32_t> sample_degrees(const Coverage& cov) {
  const size_t candidates = cov.start.size() - 1;
  const size_t chunks = std::clamp<size_t>(cov.samples.size() / (size_t(1) << 20), 1, 8);
  std::vector<std::vector<uint32_t>> part(chunks, std::vector<uint32_t>(cov.sample_count, 0));
  tbb::parallel_for(size_t(0), chunks, [&](size_t k) {
    const uint32_t* n = cov.samples.data() + cov.start[candidates * k / chunks];
    const uint32_t* end = cov.samples.data() + cov.start[candidates * (k + 1) / chunks];
    for (; n != end; ++n) ++part[k][*n];
  });
  for (size_t k = 1; k < chunks; ++k)
    for (size_t s = 0; s < cov.sample_count; ++s) part[0][s] += part[k][s];
  return std::move(part[0]);
}

// The weight of the samples in [bare, end) not yet covered, summed in order; those move to
// the front, in order, and `bare` ends past them.
double gain_of_bare(uint32_t*& bare, uint32_t* end, const char* covered, const double* weight) {
  double g = 0;
  uint32_t* out = bare;
  for (uint32_t* n = bare; n != end; ++n) {
    const uint32_t s = *n;
    if (covered[s]) continue;
    g += weight[s];
    *n = *out;
    *out++ = s;
  }
  bare = out;
  return g;
}

}  // namespace

std::vector<int> greedy_cover(const Coverage& cov, const std::vector<int>& start) {
  return greedy_cover(Coverage(cov), start);
}

std::vector<int> greedy_cover(Coverage&& cov, const std::vector<int>& start) {
  const size_t candidates = cov.start.size() - 1;
  std::vector<char> covered(cov.sample_count, 0);
  for (int c : start)
    for (uint32_t n = cov.start[size_t(c)]; n < cov.start[size_t(c) + 1]; ++n) covered[cov.samples[n]] = 1;
  // Samples few candidates cover weigh more: a sphere that takes the only cover of a hard
  // sample early saves the spheres that would chase it late.
  const std::vector<uint32_t> degree = sample_degrees(cov);
  std::vector<double> weight(cov.sample_count, 0);
  for (size_t s = 0; s < weight.size(); ++s) weight[s] = degree[s] ? 1.0 / degree[s] : 0;
  // Lazy greedy: a popped gain is recounted, and the candidate taken only if it still leads.
  // A count moves the row's covered samples behind its bare ones, the bare ones kept in order,
  // and the next count reads only those: the same sums (a covered sample added nothing), at the
  // cost of what is still bare. Late in a large cover most of a row is covered.
  std::vector<uint32_t> bare_end(cov.start.begin() + 1, cov.start.end());
  auto gain_of = [&](size_t c) {
    uint32_t* const samples = cov.samples.data();
    uint32_t* bare = samples + cov.start[c];
    const double g = gain_of_bare(bare, samples + bare_end[c], covered.data(), weight.data());
    bare_end[c] = uint32_t(bare - samples);
    return g;
  };
  // The first gains side by side (a pass over every pair); the keys are distinct, so the order
  // they are popped in does not depend on the order they were pushed in.
  std::vector<std::pair<double, int>> first(candidates);  // (gain, -index)
  tbb::parallel_for(tbb::blocked_range<size_t>(0, candidates, 256), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t c = r.begin(); c != r.end(); ++c) first[c] = {cov.row_size(c) > 0 ? gain_of(c) : -1.0, -int(c)};
  });
  first.erase(std::remove_if(first.begin(), first.end(), [](const auto& e) { return e.first < 0; }), first.end());
  std::priority_queue<std::pair<double, int>> queue(std::less<std::pair<double, int>>(), std::move(first));
  std::vector<int> chosen(start);
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
    for (uint32_t n = cov.start[c]; n < bare_end[c]; ++n) covered[cov.samples[n]] = 1;  // the rest were
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

namespace {

// shrink_cover's state: which candidates are in, how often each sample is covered, the chosen
// sphere that alone covers each sample (-1: none or several) and how many such samples each
// sphere has: a candidate makes sphere k redundant only if it covers all of k's.
class Shrink {
 public:
  Shrink(const Coverage& cov, const std::vector<int>& chosen)
      : cov_(cov), in_(cov.start.size() - 1, 0), times_(cov.sample_count, 0), owner_(cov.sample_count, -1),
        critical_(cov.start.size() - 1, 0), hits_(cov.start.size() - 1, 0) {
    for (int c : chosen) {
      in_[size_t(c)] = 1;
      account(uint32_t(c), +1);
    }
    find_owners();
  }
  bool in(uint32_t c) const { return in_[c] != 0; }
  // A candidate a move may add: not chosen, and covering something.
  bool can_add(uint32_t c) const { return !in(c) && cov_.row_size(c) > 0; }

  // The spheres c covers every sample of that only they cover (`hits`: all 0, and left so): the
  // ones adding c could make redundant. Reads the state only.
  std::vector<uint32_t> could_drop(uint32_t c, std::vector<uint32_t>& hits) const {
    std::vector<uint32_t> touched;
    for (uint32_t n = cov_.start[c]; n < cov_.start[c + 1]; ++n) {
      const int k = owner_[cov_.samples[n]];
      if (k < 0) continue;
      if (hits[size_t(k)]++ == 0) touched.push_back(uint32_t(k));
    }
    std::vector<uint32_t> could;
    for (uint32_t k : touched) {
      if (hits[k] == critical_[k]) could.push_back(k);
      hits[k] = 0;
    }
    return could;
  }
  // Whether try_add(c) could keep its move: it tries only where two spheres could go.
  bool worth_trying(uint32_t c, std::vector<uint32_t>& hits) const {
    return can_add(c) && could_drop(c, hits).size() >= 2;
  }

  // Adds c and drops the spheres it makes redundant; keeps the move when two or more go.
  bool try_add(uint32_t c) {
    const std::vector<uint32_t> could = could_drop(c, hits_);
    if (could.size() < 2) return false;
    account(c, +1);
    std::vector<uint32_t> dropped;
    for (uint32_t k : could)
      if (redundant(k)) {
        account(k, -1);
        in_[k] = 0;
        dropped.push_back(k);
      }
    if (dropped.size() >= 2) {
      in_[c] = 1;
      find_owners();
      return true;
    }
    for (uint32_t k : dropped) {
      account(k, +1);
      in_[k] = 1;
    }
    account(c, -1);
    return false;
  }

 private:
  void account(uint32_t c, int by) {
    for (uint32_t n = cov_.start[c]; n < cov_.start[c + 1]; ++n)
      times_[cov_.samples[n]] = uint32_t(int(times_[cov_.samples[n]]) + by);
  }
  bool redundant(uint32_t c) const {
    for (uint32_t n = cov_.start[c]; n < cov_.start[c + 1]; ++n)
      if (times_[cov_.samples[n]] < 2) return false;
    return true;
  }
  void find_owners() {
    std::fill(owner_.begin(), owner_.end(), -1);
    std::fill(critical_.begin(), critical_.end(), 0);
    for (size_t c = 0; c < in_.size(); ++c)
      if (in_[c])
        for (uint32_t n = cov_.start[c]; n < cov_.start[c + 1]; ++n)
          if (times_[cov_.samples[n]] == 1) {
            owner_[cov_.samples[n]] = int(c);
            ++critical_[c];
          }
  }

  const Coverage& cov_;
  std::vector<char> in_;
  std::vector<uint32_t> times_;
  std::vector<int> owner_;
  std::vector<uint32_t> critical_, hits_;
};

}  // namespace

size_t shrink_cover(const Coverage& cov, std::vector<int>& chosen) {
  const size_t candidates = cov.start.size() - 1;
  Shrink state(cov, chosen);
  size_t shrunk = 0;
  // Few moves are kept, and until one is the state stays as it was: which candidates of a chunk
  // are worth trying is asked side by side, then they are tried in order. After a kept move the
  // rest of the chunk is tried one by one, as the state now is.
  constexpr uint32_t kChunk = 4096;
  tbb::enumerable_thread_specific<std::vector<uint32_t>> hits([&] { return std::vector<uint32_t>(candidates, 0); });
  std::vector<char> worth(kChunk);
  for (int pass = 0; pass < 3; ++pass) {
    size_t this_pass = 0;
    for (uint32_t first = 0; first < candidates; first += kChunk) {
      const uint32_t last = uint32_t(std::min<size_t>(candidates, size_t(first) + kChunk));
      tbb::parallel_for(tbb::blocked_range<uint32_t>(first, last, 256), [&](const tbb::blocked_range<uint32_t>& r) {
        std::vector<uint32_t>& mine = hits.local();
        for (uint32_t c = r.begin(); c != r.end(); ++c) worth[c - first] = state.worth_trying(c, mine);
      });
      bool changed = false;
      for (uint32_t c = first; c < last; ++c)
        if ((changed || worth[c - first]) && state.can_add(c) && state.try_add(c)) {
          ++this_pass;
          changed = true;
        }
    }
    shrunk += this_pass;
    if (this_pass == 0) break;
  }
  if (shrunk > 0) {
    chosen.clear();
    for (uint32_t c = 0; c < candidates; ++c)
      if (state.in(c)) chosen.push_back(int(c));
  }
  return shrunk;
}

namespace {

// Whether sorted a is a subset of sorted b.
constexpr std::ptrdiff_t kMergeRatio = 8;
bool is_subset(const uint32_t* a, const uint32_t* a_end, const uint32_t* b, const uint32_t* b_end) {
  if (a == a_end) return true;
  // Rows that are not subsets mostly differ at their ends or middle: test those first.
  if (*a < *b || *(a_end - 1) > *(b_end - 1) || !std::binary_search(b, b_end, a[(a_end - a) / 2])) return false;
  // Rows of like length: one merge pass; a much longer b: a search per entry of a.
  if (b_end - b < kMergeRatio * (a_end - a)) {
    for (; a != a_end; ++a, ++b) {
      while (b != b_end && *b < *a) ++b;
      if (b == b_end || *b != *a) return false;
    }
    return true;
  }
  for (; a != a_end; ++a) {
    b = std::lower_bound(b, b_end, *a);
    if (b == b_end || *b != *a) return false;
  }
  return true;
}
bool row_is_subset(const Coverage& rows, uint32_t a, const Coverage& of, uint32_t b) {
  return is_subset(&rows.samples[rows.start[a]], &rows.samples[rows.start[a + 1]], &of.samples[of.start[b]],
                   &of.samples[of.start[b + 1]]);
}

// Each row's entries hashed into 256 bits: a row whose bits are not all among another's is not
// a subset of it, told in four word operations (most pairs a reduction looks at are not).
using Signature = std::array<uint64_t, 4>;
std::vector<Signature> signatures(const Coverage& rows) {
  std::vector<Signature> out(rows.start.size() - 1);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, out.size(), 1024), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t r = range.begin(); r != range.end(); ++r) {
      Signature sig{};
      for (uint32_t n = rows.start[r]; n < rows.start[r + 1]; ++n) {
        const uint64_t bit = (uint64_t(rows.samples[n]) * 0x9E3779B97F4A7C15ull) >> 56;
        sig[bit >> 6] |= uint64_t(1) << (bit & 63);
      }
      out[r] = sig;
    }
  });
  return out;
}
bool may_be_subset(const Signature& a, const Signature& b) {
  return ((a[0] & ~b[0]) | (a[1] & ~b[1]) | (a[2] & ~b[2]) | (a[3] & ~b[3])) == 0;
}

// Of the entries of row r of `rows`, the one whose own row in `of` is shortest (the first on
// ties): the only rows a subset test must scan.
uint32_t shortest_among(const Coverage& rows, size_t r, const Coverage& of) {
  uint32_t best = rows.samples[rows.start[r]];
  for (uint32_t n = rows.start[r]; n < rows.start[r + 1]; ++n)
    if (of.row_size(rows.samples[n]) < of.row_size(best)) best = rows.samples[n];
  return best;
}

// Samples: b is implied when some a's candidates are all among b's (a cover of a covers b).
// Smallest first; a kept sample marks every larger one it implies (ties: the later index). In
// parallel: which rows get marked does not depend on the order they are visited in (a row
// implied by one that is itself implied is implied by that one's implier too). Rows whose scan
// would pass `scan` imply nothing; that too depends on the row alone. `by`: cov transposed.
std::vector<std::atomic<uint8_t>> implied_samples(const Coverage& cov, const Coverage& by, uint32_t scan) {
  std::vector<uint32_t> order;
  for (uint32_t s = 0; s < cov.sample_count; ++s)
    if (by.row_size(s) > 0) order.push_back(s);
  std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return by.row_size(a) < by.row_size(b); });
  std::vector<std::atomic<uint8_t>> implied(cov.sample_count);
  const std::vector<Signature> sig = signatures(by);
  tbb::parallel_for(size_t(0), order.size(), [&](size_t k) {
    const uint32_t a = order[k];
    if (implied[a].load(std::memory_order_relaxed)) return;
    // Every sample implied by a is covered by a's candidate that covers fewest samples.
    const uint32_t rare = shortest_among(by, a, cov);
    if (cov.row_size(rare) > scan) return;
    for (uint32_t n = cov.start[rare]; n < cov.start[rare + 1]; ++n) {
      const uint32_t b = cov.samples[n];
      if (b == a || implied[b].load(std::memory_order_relaxed) || by.row_size(b) < by.row_size(a)) continue;
      if (by.row_size(b) == by.row_size(a) && b < a) continue;  // identical rows: keep the earlier
      if (may_be_subset(sig[a], sig[b]) && row_is_subset(by, a, by, b)) implied[b].store(1, std::memory_order_relaxed);
    }
  });
  return implied;
}

// Candidates: d is dominated when another covers all of its samples (ties: the later index), or
// covers none. In parallel, as above. `holders`: rows transposed.
std::vector<std::atomic<uint8_t>> dominated_candidates(const Coverage& rows, const Coverage& holders, uint32_t scan) {
  const size_t candidates = rows.start.size() - 1;
  std::vector<std::atomic<uint8_t>> dominated(candidates);
  const std::vector<Signature> sig = signatures(rows);
  tbb::parallel_for(size_t(0), candidates, [&](size_t d) {
    if (rows.row_size(d) == 0) {
      dominated[d].store(1, std::memory_order_relaxed);
      return;
    }
    const uint32_t rare = shortest_among(rows, d, holders);
    if (holders.row_size(rare) > scan) return;
    for (uint32_t n = holders.start[rare]; n < holders.start[rare + 1]; ++n) {
      const uint32_t e = holders.samples[n];
      if (e == d || dominated[e].load(std::memory_order_relaxed) || rows.row_size(e) < rows.row_size(d)) continue;
      if (rows.row_size(e) == rows.row_size(d) && e > d) continue;  // identical: keep the earlier
      if (may_be_subset(sig[d], sig[e]) && row_is_subset(rows, uint32_t(d), rows, e)) {
        dominated[d].store(1, std::memory_order_relaxed);
        break;
      }
    }
  });
  return dominated;
}

// The rows `keep` says to keep, each with only the entries `map` renumbers (UINT32_MAX: drop),
// as a Coverage of `columns`: counted, then filled, rows side by side in blocks.
template <class Keep>
Coverage filtered_rows(const Coverage& cov, size_t columns, Keep keep, const std::vector<uint32_t>* map) {
  const size_t rows = cov.start.size() - 1;
  std::vector<uint32_t> kept;
  for (size_t r = 0; r < rows; ++r)
    if (keep(r)) kept.push_back(uint32_t(r));
  auto entry = [&](uint32_t n) { return map ? (*map)[cov.samples[n]] : cov.samples[n]; };
  Coverage out;
  out.sample_count = columns;
  out.start.assign(kept.size() + 1, 0);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, kept.size(), 512), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t k = range.begin(); k != range.end(); ++k) {
      uint32_t n = 0;
      for (uint32_t i = cov.start[kept[k]]; i < cov.start[kept[k] + 1]; ++i) n += entry(i) != UINT32_MAX;
      out.start[k + 1] = n;
    }
  });
  std::partial_sum(out.start.begin(), out.start.end(), out.start.begin());
  out.samples.resize(out.start.back());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, kept.size(), 512), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t k = range.begin(); k != range.end(); ++k) {
      uint32_t* to = out.samples.data() + out.start[k];
      for (uint32_t i = cov.start[kept[k]]; i < cov.start[kept[k] + 1]; ++i)
        if (const uint32_t e = entry(i); e != UINT32_MAX) *to++ = e;
    }
  });
  return out;
}

}  // namespace

ReducedCover reduce_cover(const Coverage& cov, uint32_t scan) {
  const size_t candidates = cov.start.size() - 1;
  Coverage by = covering_candidates(cov);
  const std::vector<std::atomic<uint8_t>> implied = implied_samples(cov, by, scan);
  ReducedCover out;
  std::vector<uint32_t> row_of(cov.sample_count, UINT32_MAX);
  for (uint32_t s = 0; s < cov.sample_count; ++s)
    if (by.row_size(s) > 0 && !implied[s]) row_of[s] = uint32_t(out.sample.size()), out.sample.push_back(s);
  // The kept samples' own rows of `by` (each the candidates covering it), then the candidates'
  // rows over them, renumbered: the same pairs both ways. `by` is let go before the rows are
  // built, so that three copies of the pairs are held at once, not four (on 48 frames of the
  // elephant's walk at 64 spheres the peak fell from 2.71 to 2.23 GB).
  Coverage holders = filtered_rows(by, candidates, [&](size_t s) { return row_of[s] != UINT32_MAX; }, nullptr);
  by = {};
  const Coverage rows = filtered_rows(cov, out.sample.size(), [](size_t) { return true; }, &row_of);
  const std::vector<std::atomic<uint8_t>> dominated = dominated_candidates(rows, holders, scan);
  holders = {};
  auto is_kept = [&](size_t c) { return !dominated[c].load(std::memory_order_relaxed); };
  for (size_t c = 0; c < candidates; ++c)
    if (is_kept(c)) out.candidate.push_back(uint32_t(c));
  out.coverage = filtered_rows(rows, out.sample.size(), is_kept, nullptr);
  return out;
}

std::vector<int> smallest_cover(const Coverage& cov, SearchLimits limits, size_t enough, size_t* lower_bound, Log& log,
                                const std::vector<int>& start, std::vector<uint32_t>* kept_samples) {
  const ReducedCover reduced = reduce_cover(cov, limits.scan);
  if (kept_samples) *kept_samples = reduced.sample;
  // The start's candidates the reduction kept (one it dropped is dominated: greedy finds better).
  std::vector<int> kept;
  if (!start.empty()) {
    std::vector<int> reduced_of(cov.start.size() - 1, -1);
    for (size_t r = 0; r < reduced.candidate.size(); ++r) reduced_of[reduced.candidate[r]] = int(r);
    for (int c : start)
      if (reduced_of[size_t(c)] >= 0) kept.push_back(reduced_of[size_t(c)]);
  }
  std::vector<int> chosen = greedy_cover(reduced.coverage, kept);
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

std::vector<uint32_t> uncovered_samples(const Coverage& cov) {
  std::vector<char> any(cov.sample_count, 0);
  for (uint32_t s : cov.samples) any[s] = 1;
  std::vector<uint32_t> out;
  for (size_t s = 0; s < any.size(); ++s)
    if (!any[s]) out.push_back(uint32_t(s));
  return out;
}

Coverage covering_candidates(const Coverage& cov) {
  struct Row {
    const uint32_t *begin_, *end_;
    const uint32_t* begin() const { return begin_; }
    const uint32_t* end() const { return end_; }
  };
  return transposed(cov.start.size() - 1, cov.sample_count, [&](size_t c) {
    return Row{cov.samples.data() + cov.start[c], cov.samples.data() + cov.start[c + 1]};
  });
}

}  // namespace spx
