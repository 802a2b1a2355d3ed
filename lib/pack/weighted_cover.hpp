#pragma once
// pack internals: the row-weighting search's state (cover_search.cpp), here so that its
// incremental scores can be checked against a recount.
#include <algorithm>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include "pack/set_cover.hpp"

namespace spx::detail {

// The state of the row-weighting search: which candidates are in, how often each sample is
// covered, the samples' weights, and each candidate's score (in: minus the weight it alone
// covers, the loss of dropping it; out: the weight of bare samples it covers, the gain of
// adding it). A candidate dropped may be added back once its configuration changed: one of its
// samples turned bare or covered, or (`thorough`) its covering count changed at all at 2 or below,
// which costs a scan of that sample's candidates at each such change.
//
// Raising every bare sample's weight would touch every candidate covering one at every step, so
// it is counted instead: a bare sample's weight is its stored weight plus the raises since it
// turned bare, and a candidate's score its stored part plus its bare samples times the raises so
// far (a member covers none).
class WeightedCover {
 public:
  WeightedCover(const Coverage& cov, const Coverage& by, bool thorough) : cov_(cov), by_(by), thorough_(thorough) {
    const size_t n = cov.start.size() - 1, m = cov.sample_count;
    if (m >= size_t(kMayAdd)) throw std::length_error("cover search: more samples than a score word counts");
    count_.assign(m, 0);
    member_sum_.assign(m, 0);
    weight_.assign(m, 1);
    bare_at_.assign(m, -1);
    word_.assign(n, 0);
    bare_since_.assign(m, 0);
    stamp_.assign(n, 0);
    in_.assign(n, 0);
    for (uint32_t s = 0; s < m; ++s)
      if (by.row_size(s) > 0) make_bare(s);
    for (size_t c = 0; c < n; ++c)  // every sample starts bare, of weight 1
      word_[c] = packed(int64_t(cov.row_size(c)), int64_t(cov.row_size(c))) | kMayAdd;
  }

  void add(uint32_t c, uint64_t step) {
    work_ += cov_.row_size(c);
    in_[c] = 1;
    word_[c] = packed(-score(c), 0);
    stamp_[c] = step;
    members_.push_back(c);
    for (uint32_t k = cov_.start[c]; k < cov_.start[c + 1]; ++k) {
      const uint32_t s = cov_.samples[k];
      const uint32_t before = count_[s]++;
      if (before == 1) {
        word_[member_sum_[s]] += packed(weight_[s], 0);  // its one member no longer alone
        if (thorough_) mark_changed(s, c);
      }
      member_sum_[s] += c;
      if (before > 0) continue;
      drop_bare(s);
      shift_gains(s, c, -(weight_[s] - raised_), -1);  // no longer a gain to anyone
    }
  }

  void remove(uint32_t c, uint64_t step) {
    work_ += cov_.row_size(c);
    in_[c] = 0;
    // A member's word is its stored part alone (no bare samples); once out, it may not be added
    // until its configuration changes.
    word_[c] = -(word_[c] & ~kMayAdd);
    stamp_[c] = step;
    members_.erase(std::find(members_.begin(), members_.end(), c));
    for (uint32_t k = cov_.start[c]; k < cov_.start[c + 1]; ++k) {
      const uint32_t s = cov_.samples[k];
      const uint32_t after = --count_[s];
      member_sum_[s] -= c;
      if (after == 1) {
        word_[member_sum_[s]] -= packed(weight_[s], 0);  // its one member now alone
        if (thorough_) mark_changed(s, c);
      }
      if (after > 0) continue;
      make_bare(s);
      word_[c] += packed(-raised_, 1);
      shift_gains(s, c, weight_[s] - raised_, 1);  // a gain to every candidate covering it
    }
  }

  // Sample s became bare or covered: every candidate covering it but `changed` (none of them a
  // member) gains `delta` in its stored part and `bare` bare samples, and its configuration
  // changed: one read and one write of its word. (The bare count stays within its bits, so the
  // flag above it is kept by the sum.) `changed` is updated with the others and then given its
  // word back: no test at every entry.
  void shift_gains(uint32_t s, uint32_t changed, int64_t delta, int32_t bare) {
    const uint32_t* o = by_.samples.data() + by_.start[s];
    const uint32_t* end = by_.samples.data() + by_.start[s + 1];
    int64_t* word = word_.data();
    const int64_t step = packed(delta, bare);
    const int64_t kept = word[changed];
    work_ += uint64_t(end - o);
    // Four words read, then written: a sample's row names each candidate once, so no write
    // feeds a read of the same four, and the reads need not wait on the writes before them.
    for (; end - o >= 4; o += 4) {
      const int64_t w0 = word[o[0]], w1 = word[o[1]], w2 = word[o[2]], w3 = word[o[3]];
      word[o[0]] = (w0 + step) | kMayAdd;
      word[o[1]] = (w1 + step) | kMayAdd;
      word[o[2]] = (w2 + step) | kMayAdd;
      word[o[3]] = (w3 + step) | kMayAdd;
    }
    for (; o != end; ++o) word[*o] = (word[*o] + step) | kMayAdd;
    word[changed] = kept;
  }

  void mark_changed(uint32_t s, uint32_t changed) {
    const uint32_t* o = by_.samples.data() + by_.start[s];
    const uint32_t* end = by_.samples.data() + by_.start[s + 1];
    int64_t* word = word_.data();
    const int64_t kept = word[changed];
    work_ += uint64_t(end - o);
    for (; o != end; ++o) word[*o] |= kMayAdd;
    word[changed] = kept;
  }

  // Bare samples weigh one more, so the candidates covering them gain (counted: see above). The
  // work counts the entries a pass over them would visit, as the limits were set by.
  void raise_bare_weights() {
    work_ += bare_entries_;
    ++raised_;
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
      if (may_add(c) && (best == UINT32_MAX || better(c, best))) best = c;
    }
    return best == UINT32_MAX ? fallback : best;
  }
  bool covers_all() const { return bare_.empty(); }
  // Entries of the coverage visited so far: what the search has cost.
  uint64_t work() const { return work_; }
  size_t bare_count() const { return bare_.size(); }
  uint32_t bare(size_t i) const { return bare_[i]; }
  const std::vector<uint32_t>& members() const { return members_; }
  int64_t score(uint32_t c) const {
    const int64_t word = word_[c];
    return (word >> kBareBits) + (word & (kMayAdd - 1)) * raised_;
  }
  int64_t weight(uint32_t s) const { return weight_[s] + (bare_at_[s] >= 0 ? raised_ - bare_since_[s] : 0); }
  bool in(uint32_t c) const { return in_[c] != 0; }
  // Whether a candidate not in may be added back: its configuration changed since it left.
  bool may_add(uint32_t c) const { return (word_[c] & kMayAdd) != 0; }

 private:
  bool better(uint32_t a, uint32_t b) const {
    const int64_t sa = score(a), sb = score(b);
    return sa > sb || (sa == sb && (stamp_[a] < stamp_[b] || (stamp_[a] == stamp_[b] && a < b)));
  }
  void make_bare(uint32_t s) {
    bare_at_[s] = int64_t(bare_.size());
    bare_.push_back(s);
    bare_since_[s] = raised_;
    bare_entries_ += by_.row_size(s);
  }
  // Its weight then keeps the raises it had while bare.
  void drop_bare(uint32_t s) {
    weight_[s] += raised_ - bare_since_[s];
    bare_entries_ -= by_.row_size(s);
    const int64_t at = bare_at_[s];
    bare_[size_t(at)] = bare_.back();
    bare_at_[bare_.back()] = at;
    bare_.pop_back();
    bare_at_[s] = -1;
  }

  const Coverage& cov_;
  const Coverage& by_;
  const bool thorough_;
  std::vector<uint32_t> count_;
  std::vector<uint32_t> member_sum_;  // the sum of the members covering each sample: its one member where count is 1
  // Per candidate, one word: its score's stored part, whether it may be added, and the bare
  // samples it covers (0 for a member), stored part * 2^24 + may-add * 2^23 + bare count, so
  // that a step's update to a candidate is one read and one write. A row has fewer than 2^23
  // samples, so the count never reaches the flag, and a stored part is at most a row's samples
  // times the steps, far inside the 40 bits left. (A member's may-add is never read, and is
  // cleared when it leaves.)
  static constexpr int kBareBits = 24;
  static constexpr int64_t kBareUnit = int64_t(1) << kBareBits;
  static constexpr int64_t kMayAdd = int64_t(1) << (kBareBits - 1);
  static int64_t packed(int64_t stored, int64_t bare) { return stored * kBareUnit + bare; }
  std::vector<int64_t> word_;
  std::vector<int64_t> weight_, bare_at_, bare_since_;
  std::vector<uint64_t> stamp_;
  std::vector<char> in_;
  std::vector<uint32_t> bare_, members_;
  uint64_t work_ = 0;
  uint64_t bare_entries_ = 0;  // the bare samples' candidates, counted with repeats
  int64_t raised_ = 0;         // raises so far
};

}  // namespace spx::detail
