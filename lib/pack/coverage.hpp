#pragma once
// Coverage from geometry: the samples of one or several poses and each candidate's sphere in
// them; a candidate covers a sample within delta of its sphere (gap = |p - c| - r <= delta).
#include <functional>
#include <map>
#include <utility>
#include <vector>

#include "core/sphere.hpp"
#include "pack/set_cover.hpp"

namespace spx {

// The geometry of one cover problem: the points to cover, in one or several poses, and each
// candidate's sphere in those poses. Rows of several poses are stacked: a candidate covers a
// sample of pose k with its sphere in pose k.
struct CoverProblem {
  std::vector<std::vector<Eigen::Vector3d>> samples;  // per pose
  // Per pose: the first `weighted[k]` samples count in the total error that local improvement
  // cuts (the mesh's vertices, where the error is measured); the rest (area samples) only have
  // to stay within delta. Empty: every sample counts.
  std::vector<size_t> weighted;
  std::vector<SphereSet> spheres;                     // per pose, one per candidate (radius 0: absent)
  // Coverage at delta leaves out a candidate that another nearly contains in every pose, within
  // `merge` x delta (representatives): every sample's gap to the other is at most that much
  // more. Bounds the rows where candidates are many (one at every sample) and delta is large.
  double merge = 0;
  size_t candidate_count() const { return spheres.empty() ? 0 : spheres.front().size(); }
  size_t sample_count() const;
};

// Candidates that stand for the rest at `slack`: from the largest (pose 0's radius, ties by
// index), a candidate is left out (0) when one kept before it nearly contains it in every pose
// where it is present, |c - c'| + r - r' <= slack, so that its gap to every sample is at least
// the kept one's less `slack`. Candidates absent in pose 0 are kept.
std::vector<char> representatives(const CoverProblem& problem, double slack);

// Which samples each candidate covers at `delta`, rows of several poses stacked.
Coverage coverage_at(const CoverProblem& problem, double delta);

// The coverage at one delta of problems that follow one another, as the rounds of a constraint
// generation do: samples come and go, the candidates only grow (appended, their spheres never
// changing: clear() where they do). Each sample's covering candidates are kept while it stays
// in the problem, so that a round computes only the pairs of its new samples and new candidates,
// not every pair again, and needs no sphere of the others: a problem of samples alone.
class CoverageCache {
 public:
  // Candidate c's sphere in part k of the problem.
  using SphereOf = std::function<Sphere(size_t part, size_t candidate)>;
  explicit CoverageCache(double delta) : delta_(delta) {}
  double delta() const { return delta_; }
  // The problem's samples, per part, and `parts[k]`: those of part k as (source, indices into
  // it): the same source and index name the same point in every problem. Equals coverage_at of
  // the problem with those spheres (no `merge`).
  Coverage coverage(const std::vector<std::vector<Eigen::Vector3d>>& samples, size_t candidates,
                    const SphereOf& sphere, const std::vector<std::pair<size_t, std::vector<uint32_t>>>& parts);
  // Samples about to join (`parts` as above, `samples` per part): their columns, computed now
  // and kept for the next coverage() (which forgets those not in its problem). Returns, per part,
  // the positions in its indices of the samples no candidate covers.
  std::vector<std::vector<uint32_t>> uncovered_joining(const std::vector<std::vector<Eigen::Vector3d>>& samples,
                                                       size_t candidates, const SphereOf& sphere,
                                                       const std::vector<std::pair<size_t, std::vector<uint32_t>>>& parts);
  void clear() { columns_.clear(); }

 private:
  struct Column {
    uint32_t upto = 0;                // the candidates [0, upto) were checked
    std::vector<uint32_t> covering;   // ascending
  };
  // The stacked samples `stacked` (parts start at `offset`) against the candidates from `from` on.
  void check(const std::vector<std::vector<Eigen::Vector3d>>& samples, uint32_t candidates, const SphereOf& sphere,
             const std::vector<uint32_t>& offset, const std::vector<uint32_t>& stacked, uint32_t from,
             const std::vector<Column*>& column) const;
  // Every column of `column` (the stacked samples, parts starting at `offset`) checked against the
  // candidates up to `candidates`; a column listed twice is checked once.
  void complete(const std::vector<std::vector<Eigen::Vector3d>>& samples, uint32_t candidates, const SphereOf& sphere,
                const std::vector<uint32_t>& offset, const std::vector<Column*>& column) const;
  double delta_;
  std::map<std::pair<size_t, uint32_t>, Column> columns_;  // (source, index): the samples of the last problem
};

// The coverage at every delta up to `max_delta`, computed once: each candidate's samples with
// their gaps. at(delta), for any delta <= max_delta, is coverage_at(problem, delta) of the
// candidates that stand for the rest at merge x max_delta (all of them without `merge`). The
// table refers to `problem`, which must outlive it.
class GapTable {
 public:
  GapTable(const CoverProblem& problem, double max_delta);
  Coverage at(double delta) const;
  // Drops the pairs past `max_delta` (below the table's own): a bisection that has found a cover
  // at some delta asks only below it from then on, and each at() reads the pairs it keeps. The
  // candidates standing for the rest stay those of the table's first max_delta, so at() below
  // it gives what it gave before.
  void shrink(double max_delta);

 private:
  // Candidates in chunks as they were gathered side by side (none copied into one array). An
  // entry is a sample (the high bits) and its gap's bucket (the low shift_ bits): a monotone map of
  // the gap onto [0, 2^shift_), so a bucket below delta's is within delta and one above is not;
  // only delta's own bucket asks the geometry for the exact gap (4 bytes a pair, where a sample
  // and a double took 12).
  struct Chunk {
    std::vector<uint32_t> ends;  // one past each candidate's last entry
    std::vector<uint32_t> entries;
  };
  uint32_t bucket(double gap) const;
  bool within(size_t candidate, uint32_t sample, double delta) const;
  const CoverProblem& problem_;
  double max_delta_;
  uint32_t shift_ = 0;  // the bucket's bits
  double top_ = 0, scale_ = 0;  // the last bucket, and buckets per unit of gap
  std::vector<uint32_t> offset_;  // each pose's first stacked sample, and their count
  size_t candidates_ = 0;
  std::vector<Chunk> chunks_;
};

// For each sample, the smallest gap over every candidate: the least delta at which it can be
// covered at all (infinite where no candidate exists).
std::vector<double> least_gaps(const CoverProblem& problem);
// The same for the listed samples only (stacked indices): where a cover leaves a few samples
// bare, the least delta that reaches them costs a scan of those few, not of all.
std::vector<double> least_gaps_of(const CoverProblem& problem, const std::vector<uint32_t>& samples);

// The largest gap of the problem's samples to the union of candidates [first, first + count) as
// the problem has them: a delta at which those candidates are a cover.
double largest_gap_to(const CoverProblem& problem, size_t first, size_t count);

// The samples no sphere of `spheres` comes within `delta` of (gap > delta), ascending: what a
// chosen set leaves bare in a pose the cover was not solved on.
std::vector<uint32_t> bare_samples(const std::vector<Eigen::Vector3d>& samples, const SphereSet& spheres, double delta);

// A sphere of radius 0 in a pose only costs the host there: candidates [from..] that are 0 in
// half the poses or more are withdrawn (0 in every pose, so they cover nothing). Returns how
// many were on offer before.
size_t withdraw_mostly_absent(CoverProblem& problem, size_t from = 0);

}  // namespace spx
