#include <algorithm>
#include <limits>
#include <numeric>

#include "core/random.hpp"
#include "pack/set_cover.hpp"

namespace spx {
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

}  // namespace spx
