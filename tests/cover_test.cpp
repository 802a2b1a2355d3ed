#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numeric>
#include <random>

#include <tbb/global_control.h>

#include "core/atomic_file.hpp"
#include "io/spheres_file.hpp"
#include "io/vdb_io.hpp"
#include "mesh/union_distance.hpp"
#include "mesh/inscribed.hpp"
#include "mesh/split.hpp"
#include "pack/candidate_cache.hpp"
#include "pack/cover.hpp"
#include "pack/median_descent.hpp"
#include "pack/sample_grid.hpp"
#include "pack/two_nearest.hpp"
#include "pack/select.hpp"
#include "pack/sphere_pack_tool.hpp"
#include "pack/weighted_cover.hpp"
#include "sdf/sdf.hpp"
#include "synthetic/synthetic.hpp"
#include "test_util.hpp"

namespace spx {
namespace {

// A cover problem as rows: candidate -> samples.
Coverage coverage_of(const std::vector<std::vector<uint32_t>>& rows, size_t samples) {
  Coverage c;
  c.sample_count = samples;
  c.start.push_back(0);
  for (const auto& r : rows) {
    c.samples.insert(c.samples.end(), r.begin(), r.end());
    c.start.push_back(uint32_t(c.samples.size()));
  }
  return c;
}

bool covers_all(const Coverage& c, const std::vector<int>& chosen) {
  std::vector<char> hit(c.sample_count, 0);
  for (int k : chosen)
    for (uint32_t n = c.start[size_t(k)]; n < c.start[size_t(k) + 1]; ++n) hit[c.samples[n]] = 1;
  std::vector<char> coverable(c.sample_count, 0);
  for (uint32_t s : c.samples) coverable[s] = 1;
  for (size_t s = 0; s < c.sample_count; ++s)
    if (coverable[s] && !hit[s]) return false;
  return true;
}

// A random tiny instance: each candidate covers each sample with probability 1/4.
std::vector<std::vector<uint32_t>> random_rows(std::mt19937& rng, size_t candidates, size_t samples) {
  std::vector<std::vector<uint32_t>> rows(candidates);
  for (auto& r : rows)
    for (uint32_t s = 0; s < samples; ++s)
      if (rng() % 4 == 0) r.push_back(s);
  return rows;
}

// The brute-force optimum: the smallest subset of candidates that covers every sample.
size_t optimum(const Coverage& c) {
  const size_t n = c.start.size() - 1;
  size_t best = n;
  for (uint32_t mask = 0; mask < (1u << n); ++mask) {
    std::vector<int> chosen;
    for (size_t k = 0; k < n; ++k)
      if (mask & (1u << k)) chosen.push_back(int(k));
    if (chosen.size() < best && covers_all(c, chosen)) best = chosen.size();
  }
  return best;
}

// Small random instances against the brute-force optimum: the greedy cover is a cover, no
// chosen sphere is redundant, and lower bounds <= optimum <= greedy <= optimum * H(samples);
// the Lagrangian bound is as strong as the combinatorial one overall.
TEST(Cover, GreedyAndLowerBoundAgainstBruteForce) {
  std::mt19937 rng(3);
  size_t exact = 0, combinatorial_total = 0, lagrangian_total = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const size_t samples = 3 + rng() % 14;
    const Coverage c = coverage_of(random_rows(rng, 4 + rng() % 9, samples), samples);
    const std::vector<int> chosen = greedy_cover(c);
    ASSERT_TRUE(covers_all(c, chosen)) << "trial " << trial;
    for (size_t drop = 0; drop < chosen.size(); ++drop) {
      std::vector<int> fewer = chosen;
      fewer.erase(fewer.begin() + std::ptrdiff_t(drop));
      EXPECT_FALSE(covers_all(c, fewer)) << "trial " << trial << ": a redundant sphere was kept";
    }
    const size_t best = optimum(c), bound = cover_lower_bound(c);
    double harmonic = 0;
    for (size_t k = 1; k <= samples; ++k) harmonic += 1.0 / double(k);
    EXPECT_LE(bound, best) << "trial " << trial;
    const size_t lagrangian = lagrangian_bound(c, chosen.size());
    EXPECT_LE(lagrangian, best) << "trial " << trial;
    combinatorial_total += bound;
    lagrangian_total += lagrangian;
    EXPECT_GE(chosen.size(), best) << "trial " << trial;
    EXPECT_LE(double(chosen.size()), double(best) * harmonic) << "trial " << trial;
    exact += chosen.size() == best;
  }
  EXPECT_GT(exact, 200u) << "greedy with redundancy removal should usually be optimal on tiny cases";
  EXPECT_GE(lagrangian_total, combinatorial_total);
}

// The bound's reduced costs, four rows side by side, against one row at a time: the same bits
// for every range of rows (fewer than four, rows of every length, empty ones, a long one among
// short ones), so that the bound and the report do not move.
TEST(Cover, ReducedCostsSideBySideAreEachRowsOwnSum) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> weight(0.0, 0.3);
  for (int trial = 0; trial < 40; ++trial) {
    const size_t samples = 50 + rng() % 200, candidates = 1 + rng() % 40;
    std::vector<std::vector<uint32_t>> rows(candidates);
    for (auto& r : rows) {
      const size_t length = rng() % 7 == 0 ? 0 : rng() % 5 == 0 ? 100 + rng() % 400 : rng() % 30;
      for (size_t k = 0; k < length; ++k) r.push_back(uint32_t(rng() % samples));
    }
    const Coverage c = coverage_of(rows, samples);
    std::vector<double> u(samples);
    for (double& w : u) w = weight(rng);
    for (size_t first = 0; first < candidates; ++first)
      for (size_t end = first; end <= candidates; ++end) {
        std::vector<double> reduced(candidates, -7.0);
        detail::reduced_costs(c, u.data(), first, end, reduced.data());
        for (size_t k = 0; k < candidates; ++k) {
          double plain = -7.0;  // rows outside the range untouched
          if (k >= first && k < end) {
            plain = 1;
            for (uint32_t s : rows[k]) plain -= u[s];
          }
          ASSERT_EQ(std::memcmp(&reduced[k], &plain, sizeof plain), 0)
              << "trial " << trial << ", rows " << first << ".." << end << ", row " << k << ": " << reduced[k]
              << " against " << plain;
        }
      }
  }
}

// Greedy as written down: every candidate's gain summed afresh at every step (the weights of
// its bare samples, 1 / their degree, in row order), the largest taken, ties to the lower
// index; then the redundant spheres dropped, smallest row first.
std::vector<int> plain_greedy(const Coverage& c, const std::vector<int>& start) {
  const size_t n = c.start.size() - 1;
  std::vector<uint32_t> degree(c.sample_count, 0);
  for (uint32_t s : c.samples) ++degree[s];
  std::vector<char> covered(c.sample_count, 0);
  for (int k : start)
    for (uint32_t i = c.start[size_t(k)]; i < c.start[size_t(k) + 1]; ++i) covered[c.samples[i]] = 1;
  std::vector<int> chosen(start);
  for (;;) {
    double best = 0;
    int pick = -1;
    for (size_t k = 0; k < n; ++k) {
      double gain = 0;
      for (uint32_t i = c.start[k]; i < c.start[k + 1]; ++i)
        if (!covered[c.samples[i]]) gain += 1.0 / degree[c.samples[i]];
      if (gain > best) best = gain, pick = int(k);
    }
    if (pick < 0) break;
    chosen.push_back(pick);
    for (uint32_t i = c.start[size_t(pick)]; i < c.start[size_t(pick) + 1]; ++i) covered[c.samples[i]] = 1;
  }
  std::vector<uint32_t> times(c.sample_count, 0);
  for (int k : chosen)
    for (uint32_t i = c.start[size_t(k)]; i < c.start[size_t(k) + 1]; ++i) ++times[c.samples[i]];
  std::vector<int> order(chosen);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return c.row_size(size_t(a)) < c.row_size(size_t(b)); });
  std::vector<int> dropped;
  for (int k : order) {
    bool redundant = true;
    for (uint32_t i = c.start[size_t(k)]; i < c.start[size_t(k) + 1]; ++i) redundant = redundant && times[c.samples[i]] >= 2;
    if (!redundant) continue;
    dropped.push_back(k);
    for (uint32_t i = c.start[size_t(k)]; i < c.start[size_t(k) + 1]; ++i) --times[c.samples[i]];
  }
  chosen.erase(std::remove_if(chosen.begin(), chosen.end(),
                              [&](int k) { return std::find(dropped.begin(), dropped.end(), k) != dropped.end(); }),
               chosen.end());
  return chosen;
}

// The lazy greedy, whose counts read only the samples still bare, chooses what the plain one
// does, to the candidate and its order: rows of every length, ties everywhere (rows repeated,
// samples of equal degree), partial covers to complete; and a coverage given up to it keeps
// every row's samples.
TEST(Cover, GreedyMatchesThePlainGreedy) {
  std::mt19937 rng(17);
  for (int trial = 0; trial < 200; ++trial) {
    const size_t candidates = 5 + rng() % 60, samples = 10 + rng() % 200;
    std::vector<std::vector<uint32_t>> rows(candidates);
    for (auto& r : rows) {
      const uint32_t share = 1 + rng() % 12;  // from nearly every sample to a few
      for (uint32_t s = 0; s < samples; ++s)
        if (rng() % share == 0) r.push_back(s);
    }
    if (trial % 4 == 0) rows[rows.size() / 2] = rows.front();
    const Coverage c = coverage_of(rows, samples);
    std::vector<int> start;
    if (trial % 3 == 0) start = {int(rng() % candidates)};
    EXPECT_EQ(greedy_cover(c, start), plain_greedy(c, start)) << "trial " << trial;
    Coverage used = c;
    EXPECT_EQ(greedy_cover(std::move(used), start), plain_greedy(c, start)) << "trial " << trial;
    ASSERT_EQ(used.start, c.start) << "trial " << trial;
    for (size_t k = 0; k < candidates; ++k) {
      std::vector<uint32_t> row(used.samples.begin() + used.start[k], used.samples.begin() + used.start[k + 1]);
      std::sort(row.begin(), row.end());
      EXPECT_EQ(row, rows[k]) << "trial " << trial << ", row " << k;
    }
  }
}

// shrink_cover's rule written down, its counts taken afresh for every candidate: in candidate
// order, a candidate not chosen is added; the chosen spheres it covers every sample of that only
// they cover are dropped in turn (in the order its row first meets them) where then redundant;
// the move is kept when two or more go. Up to three passes; `moves`: the moves kept.
std::vector<int> plain_shrink(const Coverage& c, const std::vector<int>& chosen, size_t& moves) {
  const size_t n = c.start.size() - 1;
  auto row = [&](size_t k) { return std::vector<uint32_t>(c.samples.begin() + c.start[k], c.samples.begin() + c.start[k + 1]); };
  std::vector<char> in(n, 0);
  for (int k : chosen) in[size_t(k)] = 1;
  size_t kept = 0;
  for (int pass = 0; pass < 3; ++pass) {
    size_t this_pass = 0;
    for (size_t a = 0; a < n; ++a) {
      if (in[a] || c.row_size(a) == 0) continue;
      std::vector<uint32_t> times(c.sample_count, 0);
      for (size_t k = 0; k < n; ++k)
        if (in[k])
          for (uint32_t s : row(k)) ++times[s];
      std::vector<int> owner(c.sample_count, -1);
      for (size_t k = 0; k < n; ++k)
        if (in[k])
          for (uint32_t s : row(k))
            if (times[s] == 1) owner[s] = int(k);
      const std::vector<uint32_t> mine = row(a);
      std::vector<int> could;
      for (uint32_t s : mine) {
        const int k = owner[s];
        if (k < 0 || std::find(could.begin(), could.end(), k) != could.end()) continue;
        bool all = true;
        for (uint32_t t : row(size_t(k))) all = all && (owner[t] != k || std::binary_search(mine.begin(), mine.end(), t));
        if (all) could.push_back(k);
      }
      if (could.size() < 2) continue;
      for (uint32_t s : mine) ++times[s];
      std::vector<int> dropped;
      for (int k : could) {
        bool redundant = true;
        for (uint32_t s : row(size_t(k))) redundant = redundant && times[s] >= 2;
        if (!redundant) continue;
        dropped.push_back(k);
        for (uint32_t s : row(size_t(k))) --times[s];
      }
      if (dropped.size() < 2) continue;
      in[a] = 1;
      for (int k : dropped) in[size_t(k)] = 0;
      ++this_pass;
    }
    kept += this_pass;
    if (this_pass == 0) break;
  }
  moves = kept;
  if (kept == 0) return chosen;
  std::vector<int> out;
  for (size_t k = 0; k < n; ++k)
    if (in[k]) out.push_back(int(k));
  return out;
}

// shrink_cover, which asks side by side which candidates of a chunk are worth trying, keeps the
// moves the rule keeps, in order. The cover: the samples in groups, a candidate each; among the
// other candidates, unions of two or three groups (a move each, where the groups are still
// chosen) and small rows; small instances and large ones of several chunks.
TEST(Cover, ShrinkMatchesItsRule) {
  std::mt19937 rng(23);
  size_t moves = 0;
  for (int trial = 0; trial < 60; ++trial) {
    const bool large = trial % 10 == 0;
    const size_t samples = large ? 1500 : 20 + rng() % 200, others = large ? 6000 : 10 + rng() % 100;
    std::vector<std::vector<uint32_t>> groups;
    for (uint32_t s = 0; s < samples;) {
      groups.emplace_back();
      for (size_t size = 2 + rng() % 4; size > 0 && s < samples; --size) groups.back().push_back(s++);
    }
    std::vector<std::vector<uint32_t>> rows = groups;
    for (size_t k = 0; k < others; ++k) {
      std::vector<uint32_t> r;
      if (rng() % 2) {
        for (size_t n = 2 + rng() % 2; n > 0; --n) {
          const auto& g = groups[rng() % groups.size()];
          r.insert(r.end(), g.begin(), g.end());
        }
      }
      for (size_t n = rng() % 3; n > 0; --n) r.push_back(uint32_t(rng() % samples));
      std::sort(r.begin(), r.end());
      r.erase(std::unique(r.begin(), r.end()), r.end());
      rows.push_back(r);
    }
    std::vector<uint32_t> order(rows.size());
    std::iota(order.begin(), order.end(), 0u);
    std::shuffle(order.begin(), order.end(), rng);
    std::vector<std::vector<uint32_t>> shuffled(rows.size());
    std::vector<int> chosen;
    for (size_t k = 0; k < rows.size(); ++k) {
      shuffled[k] = rows[order[k]];
      if (order[k] < groups.size()) chosen.push_back(int(k));
    }
    const Coverage c = coverage_of(shuffled, samples);
    size_t expected_moves = 0;
    const std::vector<int> expected = plain_shrink(c, chosen, expected_moves);
    std::vector<int> shrunk = chosen;
    EXPECT_EQ(shrink_cover(c, shrunk), expected_moves) << "trial " << trial;
    EXPECT_EQ(shrunk, expected) << "trial " << trial;
    EXPECT_TRUE(covers_all(c, shrunk)) << "trial " << trial;
    moves += expected_moves;
  }
  EXPECT_GT(moves, 500u);
}

// Tiny random instances, some with repeated rows and columns: the reduction keeps the
// optimum and a cover of the reduced problem covers the original; the row-weighting search
// returns a cover no larger than its start and, on instances this small, the optimum.
TEST(Cover, ReductionAndSearchAgainstBruteForce) {
  std::mt19937 rng(5);
  size_t reduced_smaller = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const size_t candidates = 4 + rng() % 11, samples = 3 + rng() % 16;
    std::vector<std::vector<uint32_t>> rows = random_rows(rng, candidates, samples);
    if (trial % 3 == 0) rows.back() = rows.front();  // a repeated candidate
    const Coverage c = coverage_of(rows, samples);
    const size_t best = optimum(c);

    const ReducedCover r = reduce_cover(c);
    ASSERT_EQ(r.candidate.size(), r.coverage.start.size() - 1);
    ASSERT_EQ(r.sample.size(), r.coverage.sample_count);
    EXPECT_EQ(optimum(r.coverage), best) << "trial " << trial;
    reduced_smaller += r.candidate.size() < candidates;
    std::vector<int> back = greedy_cover(r.coverage);
    for (int& k : back) k = int(r.candidate[size_t(k)]);
    EXPECT_TRUE(covers_all(c, back)) << "trial " << trial;

    for (bool thorough : {false, true}) {
      std::vector<int> searched = greedy_cover(c);
      const size_t start = searched.size();
      local_search_cover(c, searched, {2000, 1000000000, UINT32_MAX, thorough});
      EXPECT_TRUE(covers_all(c, searched)) << "trial " << trial;
      EXPECT_LE(searched.size(), start) << "trial " << trial;
      EXPECT_EQ(searched.size(), best) << "trial " << trial << (thorough ? ", thorough" : "");
    }

    // The samples the reduction kept: a cover of them covers every sample some candidate covers,
    // since each other's candidates include all of some kept sample's.
    std::vector<uint32_t> kept;
    smallest_cover(c, {2000, 1000000000}, 0, nullptr, Log::silent(), {}, &kept);
    EXPECT_EQ(kept, r.sample) << "trial " << trial;
    const Coverage by_sample = covering_candidates(c);
    auto column = [&](uint32_t s) {
      return std::vector<uint32_t>(by_sample.samples.begin() + by_sample.start[s],
                                   by_sample.samples.begin() + by_sample.start[s + 1]);
    };
    for (uint32_t s = 0; s < samples; ++s) {
      if (by_sample.row_size(s) == 0) continue;
      const std::vector<uint32_t> mine = column(s);
      bool implied = false;
      for (uint32_t k : kept) {
        const std::vector<uint32_t> theirs = column(k);
        implied = implied || std::includes(mine.begin(), mine.end(), theirs.begin(), theirs.end());
      }
      EXPECT_TRUE(implied) << "trial " << trial << ": sample " << s << " is neither kept nor implied by one kept";
    }

    size_t bound = 0;
    const std::vector<int> smallest = smallest_cover(c, {2000, 1000000000}, 0, &bound);
    EXPECT_TRUE(covers_all(c, smallest)) << "trial " << trial;
    EXPECT_EQ(smallest.size(), best) << "trial " << trial;
    EXPECT_LE(bound, best) << "trial " << trial;
  }
  EXPECT_GT(reduced_smaller, 100u) << "the reduction should drop dominated candidates";
}

// A ball query visits every sample within reach, each once, with cells fixed or by density: on
// dense and sparse point sets, flat ones (a box of no volume) and a single point, and for reaches
// up to 1e209, against a scan.
TEST(Cover, SampleGridVisitsEverySampleWithinReach) {
  std::mt19937 rng(23);
  std::uniform_real_distribution<double> u(0, 1);
  for (int trial = 0; trial < 40; ++trial) {
    const size_t n = trial % 10 == 0 ? 1 : (trial % 2 ? 20 + rng() % 60 : 2000 + rng() % 3000);
    std::vector<Eigen::Vector3d> points(n);
    for (auto& p : points) p = {10 * u(rng), 4 * u(rng), trial % 3 == 0 ? 0.0 : 2 * u(rng)};
    for (bool by_density : {false, true}) {
      const detail::SampleGrid grid(points, by_density);
      for (int q = 0; q < 50; ++q) {
        const Eigen::Vector3d c(12 * u(rng) - 1, 6 * u(rng) - 1, 4 * u(rng) - 1);
        // Now and then a reach past any int of cells (a tolerance of 1e9): every sample.
        const double reach = q % 10 == 9 ? std::pow(10.0, 9 + q % 7 * 40) : 3 * u(rng) * u(rng);
        std::vector<int> seen(n, 0);
        grid.near(c, reach, [&](uint32_t i) { ++seen[i]; });
        for (size_t i = 0; i < n; ++i) {
          ASSERT_LE(seen[i], 1) << "trial " << trial << ", sample " << i;
          if ((points[i] - c).norm() <= reach) ASSERT_EQ(seen[i], 1) << "trial " << trial << ", sample " << i;
        }
      }
    }
  }
}

// The refinement's union of two balls' samples, gathered as the first ball's plus the samples of
// the second's cells outside the first's: the same samples as both queries, each once.
TEST(Cover, SampleGridCellsOutsideAnotherBallGiveTheUnion) {
  std::mt19937 rng(29);
  std::uniform_real_distribution<double> u(0, 1);
  for (int trial = 0; trial < 30; ++trial) {
    std::vector<Eigen::Vector3d> points(500 + rng() % 3000);
    for (auto& p : points) p = {10 * u(rng), 4 * u(rng), 2 * u(rng)};
    const detail::SampleGrid grid(points, trial % 2 == 0);
    for (int q = 0; q < 50; ++q) {
      const Eigen::Vector3d a(12 * u(rng) - 1, 6 * u(rng) - 1, 4 * u(rng) - 1);
      const Eigen::Vector3d b = q % 3 == 0 ? Eigen::Vector3d(12 * u(rng) - 1, 6 * u(rng) - 1, 4 * u(rng) - 1)
                                           : Eigen::Vector3d(a + 0.3 * Eigen::Vector3d(u(rng), u(rng), u(rng)));
      const double ra = 2 * u(rng), rb = 2 * u(rng);
      std::vector<int> both(points.size(), 0), gathered(points.size(), 0);
      grid.near(a, ra, [&](uint32_t i) { both[i] = 1; });
      grid.near(b, rb, [&](uint32_t i) { both[i] = 1; });
      grid.near(a, ra, [&](uint32_t i) { ++gathered[i]; });
      grid.visit_cells(grid.cells_near(b, rb), grid.cells_near(a, ra), [&](uint32_t i) {
        ++gathered[i];
        return false;
      });
      for (size_t i = 0; i < points.size(); ++i) ASSERT_EQ(gathered[i], both[i]) << "trial " << trial << ", sample " << i;
    }
  }
}

// A sample's two nearest spheres after one moved, against ranking them all again: over random
// moves with many equal gaps (ties go to the lower index), the moved sphere first, second or
// neither before and after.
TEST(Cover, TwoNearestAfterAMoveMatchesARankingOfAll) {
  std::mt19937 rng(31);
  for (int trial = 0; trial < 2000; ++trial) {
    const size_t n = 1 + rng() % 8;
    std::vector<double> gaps(n);
    for (double& g : gaps) g = double(rng() % 6) - 2;
    auto gap = [&](size_t j) { return gaps[j]; };
    detail::TwoNearest t = detail::two_nearest(n, gap);
    for (int move = 0; move < 20; ++move) {
      const size_t j = rng() % n;
      const double old = gaps[j];
      gaps[j] = double(rng() % 6) - 2;
      t = detail::two_nearest_after_move(t, j, old, n, gap);
      const detail::TwoNearest all = detail::two_nearest(n, gap);
      ASSERT_EQ(t.first, all.first) << "trial " << trial << ", move " << move;
      ASSERT_EQ(t.second, all.second) << "trial " << trial << ", move " << move;
    }
  }
}

// The reduction drops exactly what its rules say, on instances with many nested rows (discs
// over points in the plane): a sample whose candidates include all of another's (the smaller,
// or on a tie the earlier, is kept), then a candidate whose kept samples are all another's (the
// larger, or on a tie the earlier, is kept) or that covers none; against a scan of every pair.
TEST(Cover, ReductionDropsExactlyTheImpliedAndDominated) {
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> u(0, 1);
  auto subset = [](const std::vector<uint32_t>& a, const std::vector<uint32_t>& b) {
    return std::includes(b.begin(), b.end(), a.begin(), a.end());
  };
  auto dropped = [&](const std::vector<std::vector<uint32_t>>& sets, size_t x) {
    for (size_t y = 0; y < sets.size(); ++y)
      if (y != x && !sets[y].empty() && subset(sets[y], sets[x]) &&
          (sets[y].size() < sets[x].size() || y < x))
        return true;
    return false;
  };
  for (int trial = 0; trial < 20; ++trial) {
    const size_t candidates = 60 + rng() % 120, samples = 100 + rng() % 300;
    std::vector<Eigen::Vector2d> points(samples);
    for (auto& p : points) p = {u(rng), u(rng)};
    std::vector<std::vector<uint32_t>> rows(candidates);
    for (auto& r : rows) {
      const Eigen::Vector2d c(u(rng), u(rng));
      const double radius = 0.05 + 0.2 * u(rng);
      for (uint32_t s = 0; s < samples; ++s)
        if ((points[s] - c).norm() <= radius) r.push_back(s);
    }
    if (trial % 2 == 0) rows[1] = rows[0];  // a repeated candidate
    const Coverage c = coverage_of(rows, samples);
    const ReducedCover r = reduce_cover(c);
    std::vector<std::vector<uint32_t>> columns(samples);
    for (uint32_t k = 0; k < candidates; ++k)
      for (uint32_t s : rows[k]) columns[s].push_back(k);
    std::vector<uint32_t> kept;
    for (uint32_t s = 0; s < samples; ++s)
      if (!columns[s].empty() && !dropped(columns, s)) kept.push_back(s);
    ASSERT_EQ(r.sample, kept) << "trial " << trial;
    std::vector<std::vector<uint32_t>> over_kept(candidates);
    for (uint32_t k = 0; k < candidates; ++k)
      for (size_t n = 0; n < kept.size(); ++n)
        if (std::binary_search(rows[k].begin(), rows[k].end(), kept[n])) over_kept[k].push_back(uint32_t(n));
    std::vector<uint32_t> useful;
    for (uint32_t k = 0; k < candidates; ++k) {
      bool beaten = over_kept[k].empty();
      for (uint32_t e = 0; e < candidates && !beaten; ++e)
        beaten = e != k && subset(over_kept[k], over_kept[e]) && (over_kept[k].size() < over_kept[e].size() || e < k);
      if (!beaten) useful.push_back(k);
    }
    EXPECT_EQ(r.candidate, useful) << "trial " << trial;
    EXPECT_LT(kept.size(), samples * 3 / 4) << "trial " << trial << ": the instance should nest";
    EXPECT_LT(useful.size(), candidates) << "trial " << trial << ": some candidate should be dominated";
  }
}

// bare_samples against a scan of every pair by the coverage rule (|p - c| - r <= delta; a sphere
// of radius 0 covers nothing), from sparse spheres to spheres that overlap many times over (where
// most samples a ball reaches are already covered and passed over).
TEST(Cover, BareSamplesMatchAScanOfEveryPair) {
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int trial = 0; trial < 12; ++trial) {
    std::vector<Eigen::Vector3d> samples(2000 + rng() % 2000);
    for (auto& p : samples) p = Eigen::Vector3d(u(rng), u(rng), 0.3 * u(rng));
    SphereSet spheres(trial % 2 ? 4 + size_t(trial) : 20 + 40 * size_t(trial));
    const double largest = trial % 2 ? 0.6 : 0.15;
    for (Sphere& s : spheres)
      s = {Eigen::Vector3d(u(rng), u(rng), 0.3 * u(rng)), rng() % 7 == 0 ? 0.0 : largest * (0.5 + 0.5 * u(rng))};
    const double delta = 0.02 * (trial % 3);
    std::vector<uint32_t> expected;
    for (uint32_t i = 0; i < samples.size(); ++i) {
      bool covered = false;
      for (const Sphere& s : spheres) covered = covered || (s.radius > 0 && (samples[i] - s.center).norm() - s.radius <= delta);
      if (!covered) expected.push_back(i);
    }
    EXPECT_EQ(bare_samples(samples, spheres, delta), expected) << "trial " << trial;
    EXPECT_GT(expected.size(), 0u) << "trial " << trial;
    EXPECT_LT(expected.size(), samples.size()) << "trial " << trial;
  }
}

// The search's incremental scores against a recount after every move, both configuration
// rules: a member's score is minus the weight of the samples it alone covers (found through the
// sum of the members covering each sample), a non-member's the weight of the bare samples it
// covers. Random adds, removes and weight raises on random instances, with repeated rows. And
// whether each non-member may be added, against the rule kept apart: not once it left, again
// once a sample of its turned bare or covered (thorough: or its count changed at 2 or below).
TEST(Cover, SearchScoresAgainstRecount) {
  std::mt19937 rng(11);
  for (int trial = 0; trial < 60; ++trial) {
    const size_t candidates = 5 + rng() % 30, samples = 5 + rng() % 40;
    std::vector<std::vector<uint32_t>> rows = random_rows(rng, candidates, samples);
    if (trial % 2 == 0) rows[1] = rows[0];
    const Coverage c = coverage_of(rows, samples), by = covering_candidates(c);
    const bool thorough = trial % 3 == 0;
    detail::WeightedCover state(c, by, thorough);
    std::vector<char> may(candidates, 1);
    std::vector<uint32_t> before(samples, 0);  // each sample's count as the moves so far leave it
    for (uint64_t step = 1; step <= 200; ++step) {
      const uint32_t k = uint32_t(rng() % candidates);
      const bool adding = !state.in(k);
      if (adding) state.add(k, step);
      else state.remove(k, step);
      for (uint32_t s : rows[k]) {
        const uint32_t from = before[s], to = adding ? from + 1 : from - 1;
        before[s] = to;
        if (std::min(from, to) == 0 || (thorough && std::min(from, to) == 1))
          for (uint32_t o = 0; o < candidates; ++o)
            if (o != k && std::binary_search(rows[o].begin(), rows[o].end(), s)) may[o] = 1;
      }
      if (!adding) may[k] = 0;
      if (rng() % 3 == 0) state.raise_bare_weights();
      std::vector<uint32_t> count(samples, 0);
      for (uint32_t m : state.members())
        for (uint32_t s : rows[m]) ++count[s];
      for (uint32_t o = 0; o < candidates; ++o) {
        int64_t expected = 0;
        for (uint32_t s : rows[o])
          if (state.in(o) ? count[s] == 1 : count[s] == 0) expected += state.in(o) ? -state.weight(s) : state.weight(s);
        ASSERT_EQ(state.score(o), expected) << "trial " << trial << ", step " << step << ", candidate " << o;
        if (!state.in(o))
          ASSERT_EQ(state.may_add(o), may[o] != 0) << "trial " << trial << ", step " << step << ", candidate " << o;
      }
      size_t bare = 0;
      for (uint32_t s = 0; s < samples; ++s) bare += count[s] == 0 && by.row_size(s) > 0;
      ASSERT_EQ(state.bare_count(), bare) << "trial " << trial << ", step " << step;
    }
  }
}

// The two searches side by side give the same cover whatever the threads, and the thorough
// rule's search alike, and greedy.
TEST(Cover, SearchIndependentOfThreads) {
  std::mt19937 rng(13);
  for (int trial = 0; trial < 20; ++trial) {
    const size_t candidates = 200, samples = 300;
    const Coverage c = coverage_of(random_rows(rng, candidates, samples), samples);
    for (bool thorough : {false, true}) {
      const SearchLimits limits{3000, 1000000000, UINT32_MAX, thorough};
      std::vector<int> wide = greedy_cover(c), one = wide;
      local_search_cover(c, wide, limits);
      {
        tbb::global_control single(tbb::global_control::max_allowed_parallelism, 1);
        local_search_cover(c, one, limits);
      }
      EXPECT_TRUE(covers_all(c, wide));
      EXPECT_EQ(wide, one) << "trial " << trial << (thorough ? ", thorough" : "");
    }
  }
  // Greedy's degrees and first gains are counted side by side on problems of millions of pairs.
  const Coverage big = coverage_of(random_rows(rng, 4000, 3000), 3000);
  ASSERT_GT(big.samples.size(), size_t(2) << 20);
  const std::vector<int> wide = greedy_cover(big);
  tbb::global_control single(tbb::global_control::max_allowed_parallelism, 1);
  EXPECT_EQ(wide, greedy_cover(big));
  EXPECT_TRUE(covers_all(big, wide));
}

// Candidates offered again from alike frames: distinct_centres keeps, in order, each centre at
// least the spacing from every centre kept before (the old ones and those it took), and drops
// only those nearer; against a brute-force scan of every pair.
TEST(Cover, DistinctCentresAgainstBruteForce) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0, 1);
  for (int trial = 0; trial < 50; ++trial) {
    SphereSet old(size_t(trial % 5) * 10), more(200);
    for (auto* set : {&old, &more})
      for (Sphere& s : *set) s = {Eigen::Vector3d(u(rng), u(rng), u(rng)), 0.1};
    const double spacing = 0.05 + 0.1 * u(rng);
    const std::vector<size_t> taken = distinct_centres(old, more, spacing);
    std::vector<Eigen::Vector3d> before;
    for (const Sphere& s : old) before.push_back(s.center);
    size_t next = 0;
    for (size_t i = 0; i < more.size(); ++i) {
      bool near = false;
      for (const auto& b : before) near = near || (b - more[i].center).norm() < spacing;
      const bool kept = next < taken.size() && taken[next] == i;
      EXPECT_EQ(kept, !near) << "trial " << trial << ", candidate " << i;
      if (kept) {
        before.push_back(more[i].center);
        ++next;
      }
    }
    EXPECT_EQ(next, taken.size()) << "trial " << trial;
  }
}

// The pairs turned round in chunks side by side, against a pair by pair list: several chunks
// (rows past 4096 each), empty rows and columns, and the same result on one thread.
TEST(Cover, TransposedMatchesPairByPair) {
  std::mt19937 rng(5);
  for (size_t rows : {size_t(3), size_t(5000), size_t(70001)}) {
    const size_t columns = 300;
    std::vector<std::vector<uint32_t>> row(rows);
    for (auto& r : row) {
      const size_t n = rng() % 7;  // some empty
      for (size_t k = 0; k < n; ++k) r.push_back(uint32_t(rng() % (columns - 10)));  // the last 10 columns empty
      std::sort(r.begin(), r.end());
      r.erase(std::unique(r.begin(), r.end()), r.end());
    }
    std::vector<std::vector<uint32_t>> expected(columns);
    for (size_t r = 0; r < rows; ++r)
      for (uint32_t c : row[r]) expected[c].push_back(uint32_t(r));
    auto check = [&](const Coverage& t) {
      ASSERT_EQ(t.sample_count, rows);
      ASSERT_EQ(t.start.size(), columns + 1);
      for (size_t c = 0; c < columns; ++c)
        EXPECT_EQ(std::vector<uint32_t>(t.samples.begin() + t.start[c], t.samples.begin() + t.start[c + 1]), expected[c])
            << rows << " rows, column " << c;
    };
    auto row_of = [&](size_t r) -> const std::vector<uint32_t>& { return row[r]; };
    const Coverage both = transposed(rows, columns, row_of);
    check(both);
    tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
    const Coverage single = transposed(rows, columns, row_of);
    EXPECT_EQ(single.samples, both.samples);
    EXPECT_EQ(single.start, both.start);
  }
}

// The coverage rows against a brute-force scan of every (candidate, sample) pair.
TEST(Cover, CoverageRowsMatchBruteForce) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  CoverProblem p;
  p.samples.resize(2);
  p.spheres.resize(2);
  for (int k = 0; k < 2; ++k) {
    for (int i = 0; i < 300; ++i) p.samples[size_t(k)].emplace_back(u(rng), u(rng), u(rng));
    for (int c = 0; c < 40; ++c) p.spheres[size_t(k)].push_back({Eigen::Vector3d(u(rng), u(rng), u(rng)), c % 7 == 0 ? 0.0 : 0.3 * (u(rng) + 1)});
  }
  const double delta = 0.15;
  const Coverage cov = coverage_at(p, delta);
  const std::vector<double> least = least_gaps(p);
  for (size_t c = 0; c < 40; ++c) {
    std::vector<uint32_t> want;
    for (size_t k = 0; k < 2; ++k)
      for (size_t i = 0; i < 300; ++i) {
        const Sphere& s = p.spheres[k][c];
        if (s.radius > 0 && (p.samples[k][i] - s.center).norm() - s.radius <= delta) want.push_back(uint32_t(k * 300 + i));
      }
    const std::vector<uint32_t> got(cov.samples.begin() + cov.start[c], cov.samples.begin() + cov.start[c + 1]);
    EXPECT_EQ(got, want) << "candidate " << c;
  }
  for (size_t k = 0; k < 2; ++k)
    for (size_t i = 0; i < 300; ++i) {
      double best = std::numeric_limits<double>::infinity();
      for (const Sphere& s : p.spheres[k])
        if (s.radius > 0) best = std::min(best, (p.samples[k][i] - s.center).norm() - s.radius);
      EXPECT_DOUBLE_EQ(least[k * 300 + i], best);
    }
  const std::vector<uint32_t> some{599, 0, 300, 17};
  const std::vector<double> least_some = least_gaps_of(p, some);
  for (size_t n = 0; n < some.size(); ++n) EXPECT_DOUBLE_EQ(least_some[n], least[some[n]]) << "sample " << some[n];
}

// Rounds of a constraint generation: samples of four sources come and go, candidates are
// appended, one radius changes (then the cache is cleared): the kept pairs give, round after
// round, exactly the coverage computed whole, also with samples checked ahead of joining.
TEST(Cover, CoverageCacheMatchesCoverageOverRounds) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  const size_t sources = 4, points = 200;
  std::vector<std::vector<Eigen::Vector3d>> all(sources);
  std::vector<SphereSet> spheres(sources);  // per source, one per candidate
  for (auto& pts : all)
    for (size_t i = 0; i < points; ++i) pts.emplace_back(u(rng), u(rng), u(rng));
  auto add_candidates = [&](size_t n) {
    for (auto& set : spheres)
      for (size_t c = 0; c < n; ++c) set.push_back({Eigen::Vector3d(u(rng), u(rng), u(rng)), rng() % 6 == 0 ? 0.0 : 0.25 * (u(rng) + 1)});
  };
  const double delta = 0.12;
  CoverageCache cache(delta);
  add_candidates(15);
  std::vector<std::vector<char>> in(sources, std::vector<char>(points, 0));
  for (int round = 0; round < 8; ++round) {
    if (round > 0) add_candidates(round % 3 == 0 ? 0 : 7);
    if (round == 5) {  // a radius lowered: the kept pairs no longer hold
      for (auto& set : spheres) set[3].radius *= 0.5;
      cache.clear();
    }
    for (auto& flags : in)
      for (char& f : flags) f = rng() % 3 == 0 ? char(!f) : f;  // a third of the samples come or go
    std::vector<std::pair<size_t, std::vector<uint32_t>>> parts;
    CoverProblem problem;
    for (size_t src = 0; src < sources; ++src) {
      if (src == size_t(round) % sources) continue;  // one source sits out each round
      std::vector<uint32_t> which;
      for (uint32_t i = 0; i < points; ++i)
        if (in[src][i]) which.push_back(i);
      std::vector<Eigen::Vector3d> pts;
      for (uint32_t i : which) pts.push_back(all[src][i]);
      problem.samples.push_back(pts);
      problem.spheres.push_back(spheres[src]);
      parts.emplace_back(src, which);
    }
    // Samples about to join, some in this problem and some not, checked ahead: those no
    // candidate covers, against a scan of every candidate; the coverage after is unchanged.
    std::vector<std::pair<size_t, std::vector<uint32_t>>> joining;
    std::vector<std::vector<Eigen::Vector3d>> joining_points;
    for (size_t src = 0; src < sources; ++src) {
      joining.emplace_back(src, std::vector<uint32_t>{});
      joining_points.emplace_back();
      for (uint32_t i = 0; i < points; ++i)
        if (rng() % 4 == 0) joining.back().second.push_back(i), joining_points.back().push_back(all[src][i]);
    }
    const std::vector<std::vector<uint32_t>> uncovered = cache.uncovered_joining(
        joining_points, spheres[0].size(), [&](size_t k, size_t c) { return spheres[joining[k].first][c]; }, joining);
    for (size_t k = 0; k < joining.size(); ++k) {
      std::vector<uint32_t> bare;
      for (uint32_t n = 0; n < joining_points[k].size(); ++n) {
        bool covered = false;
        for (const Sphere& sp : spheres[joining[k].first])
          covered = covered || (sp.radius > 0 && (joining_points[k][n] - sp.center).norm() - sp.radius <= delta);
        if (!covered) bare.push_back(n);
      }
      EXPECT_EQ(uncovered[k], bare) << "round " << round << ", source " << k;
    }
    const Coverage want = coverage_at(problem, delta);
    const Coverage got = cache.coverage(problem.samples, problem.candidate_count(),
                                        [&](size_t k, size_t c) { return spheres[parts[k].first][c]; }, parts);
    EXPECT_EQ(got.sample_count, want.sample_count) << "round " << round;
    EXPECT_EQ(got.start, want.start) << "round " << round;
    EXPECT_EQ(got.samples, want.samples) << "round " << round;
  }
}

CoverProblem problem_of(const TriMesh& mesh, int resolution, std::unique_ptr<MeshQuery>& query) {
  SdfOptions o;
  o.resolution = resolution;
  const SdfResult sdf = build_sdf(mesh, o);
  query = std::make_unique<MeshQuery>(mesh);
  CoverProblem p;
  p.spheres.push_back(inscribed_candidates(sdf.field, *query, {}));
  p.samples.push_back(surface_samples(mesh, 500, 1));
  p.weighted.push_back(mesh.vertices.size());
  return p;
}

// A field's candidates offered on demand are those inscribed_candidates gives, each offered once
// and exactly when some point asked is within reach of it (brute force over every candidate):
// the extent that skips voxels before their candidates are found never skips one that counts.
TEST(Candidates, OnDemandOffersWhatTheWholeSetWouldNearThePoints) {
  // Grown (closed meshes) and bounded by the field instead (as open meshes are).
  for (const bool open : {false, true}) {
    const TriMesh mesh = make_barrel().rest;
    SdfOptions o;
    o.resolution = 48;
    const DenseField field = build_sdf(mesh, o).field;
    const MeshQuery query(mesh);
    CandidateOptions options;
    options.field_bounds_radius = open;
    const SphereSet all = inscribed_candidates(field, query, options);
    ASSERT_GT(all.size(), 100u);
    CandidatesOnDemand pool(field, options);
    const std::vector<Eigen::Vector3d> samples = surface_samples(mesh, 300, 7);
    const double reach = 0.01 * mesh.diagonal();
    std::vector<char> offered(all.size(), 0);
    size_t total = 0;
    // Three asks of a few points each, the last repeating the first.
    for (const size_t from : {size_t(0), size_t(100), size_t(0)}) {
      const std::vector<Eigen::Vector3d> points(samples.begin() + long(from), samples.begin() + long(from + 40));
      std::vector<Sphere> expected;
      for (size_t c = 0; c < all.size(); ++c) {
        if (offered[c]) continue;
        bool near = false;
        for (const auto& p : points) near = near || (p - all[c].center).norm() - all[c].radius <= reach;
        if (near) {
          offered[c] = 1;
          expected.push_back(all[c]);
        }
      }
      const SphereSet got = pool.offer_near(points, reach, query);
      ASSERT_EQ(got.size(), expected.size()) << (open ? "open" : "closed") << " from " << from;
      for (size_t n = 0; n < got.size(); ++n) {
        EXPECT_EQ(got[n].center, expected[n].center);
        EXPECT_EQ(got[n].radius, expected[n].radius);
      }
      total += got.size();
    }
    EXPECT_GT(total, 0u);
    EXPECT_LT(pool.found(), all.size()) << "every candidate was found: the extent skipped none";
  }
}

// Candidates are inscribed (center inside, radius the exact distance), budgets are never
// exceeded, the lower bound never passes the count, and the cover meets its delta at every
// sample: the max vertex error measured independently is at most delta.
TEST(Cover, BudgetsAreKeptAndDeltaIsMet) {
  const SampleAsset barrel = make_barrel();
  std::unique_ptr<MeshQuery> query;
  const CoverProblem p = problem_of(barrel.rest, 48, query);
  ASSERT_GT(p.candidate_count(), 50u);
  for (const Sphere& s : p.spheres[0]) {
    EXPECT_TRUE(query->inside(s.center));
    EXPECT_LE(s.radius, query->distance(s.center));
  }
  double last = std::numeric_limits<double>::infinity();
  for (size_t budget : {1, 2, 3, 5, 8, 16, 40}) {
    const CoverResult r = cover_with_budget(p, budget);
    EXPECT_LE(r.chosen.size(), budget);
    EXPECT_GE(r.chosen.size(), 1u);
    EXPECT_LE(r.lower_bound, r.chosen.size());
    EXPECT_EQ(r.uncoverable(), 0u);
    SphereSet spheres;
    for (int c : r.chosen) spheres.push_back(p.spheres[0][size_t(c)]);
    const std::vector<double> d = union_signed_distance(p.samples[0], spheres);
    for (double v : d) {
      EXPECT_LE(v, r.delta * (1 + 1e-12)) << "budget " << budget;
      EXPECT_GE(v, -1e-9) << "a sample inside an inscribed sphere";
    }
    EXPECT_LE(r.least_max_delta, last * (1 + 1e-9)) << "a larger budget gave a larger least max error";
    last = r.least_max_delta;
  }
  const CoverResult t = cover_within(p, 0.01);
  SphereSet spheres;
  for (int c : t.chosen) spheres.push_back(p.spheres[0][size_t(c)]);
  EXPECT_LE(vertex_error(barrel.rest, spheres).max, 0.01 * (1 + 1e-12));
  EXPECT_LE(t.lower_bound, t.chosen.size());
}

// Budget mode started where a cover of the budget is known (the polish's start): no greedy
// bisection, no more spheres than the budget, every sample within the delta it claims, and a
// least max delta no larger than the known one.
TEST(Cover, BudgetFromAKnownDeltaMeetsIt) {
  std::unique_ptr<MeshQuery> query;
  const TriMesh mesh = make_car().rest;
  const CoverProblem p = problem_of(mesh, 48, query);
  for (size_t budget : {6, 12, 24}) {
    const CoverResult plain = cover_with_budget(p, budget, kRefinedBudgetSlack);
    const CoverResult from = cover_with_budget(p, budget, kRefinedBudgetSlack, 1e-2, Log::silent(), plain.delta);
    EXPECT_LE(from.chosen.size(), budget);
    EXPECT_LT(from.evaluations, plain.evaluations) << "greedy's bisection ran anyway";
    EXPECT_LE(from.least_max_delta, plain.delta * (1 + 1e-12));
    SphereSet spheres;
    for (int c : from.chosen) spheres.push_back(p.spheres[0][size_t(c)]);
    for (double v : union_signed_distance(p.samples[0], spheres)) EXPECT_LE(v, from.delta * (1 + 1e-12)) << budget;
  }
}

// Median descent: from the same cover with spare budget, the vertices' median error (measured
// apart, on the union of the chosen spheres) is lower than after the total-error swaps alone,
// their largest error no higher, and every sample still within delta.
TEST(Cover, MedianDescentLowersTheMedianNotTheMax) {
  std::unique_ptr<MeshQuery> query;
  const TriMesh mesh = make_car().rest;
  const CoverProblem p = problem_of(mesh, 48, query);
  const Coverage cov = coverage_at(p, 0.06 * mesh.diagonal());
  const std::vector<int> start = smallest_cover(cov, kBudgetSearch, 0, nullptr);
  const size_t budget = start.size() + 4;
  auto stats = [&](const std::vector<int>& chosen) {
    SphereSet spheres;
    for (int c : chosen) spheres.push_back(p.spheres[0][size_t(c)]);
    const std::vector<double> all = union_signed_distance(p.samples[0], spheres);
    std::vector<double> vertices(all.begin(), all.begin() + long(p.weighted[0]));
    const double largest_sample = *std::max_element(all.begin(), all.end());
    const double largest = *std::max_element(vertices.begin(), vertices.end());
    std::nth_element(vertices.begin(), vertices.begin() + long(vertices.size() / 2), vertices.end());
    return std::array<double, 3>{vertices[vertices.size() / 2], largest, largest_sample};
  };
  std::vector<int> sum_only = start, descended = start;
  improve_cover(p, cov, 0.06 * mesh.diagonal(), budget, sum_only);
  improve_cover(p, cov, 0.06 * mesh.diagonal(), budget, descended, Log::silent(), true);
  ASSERT_EQ(descended.size(), sum_only.size());
  const auto before = stats(sum_only), after = stats(descended);
  EXPECT_LT(after[0], 0.98 * before[0]) << "median " << before[0] << " -> " << after[0];
  EXPECT_LE(after[1], before[1] * (1 + 1e-12)) << "the vertices' largest error rose";
  EXPECT_LE(after[2], 0.06 * mesh.diagonal() * (1 + 1e-12)) << "a sample left delta";
}

// The refinement off the grid in budget mode (keep_max) lowers the vertices' largest error and
// their median, where the same refinement trading the max for the total raises it; the spheres
// stay inside (their radii the exact distance).
TEST(Cover, RefinementLowersTheMaxWhenAsked) {
  std::unique_ptr<MeshQuery> query;
  const TriMesh mesh = make_car().rest;
  const CoverProblem p = problem_of(mesh, 48, query);
  const CoverResult r = cover_with_budget(p, 12);
  SphereSet start;
  for (int c : r.chosen) start.push_back(p.spheres[0][size_t(c)]);
  auto largest = [&](const SphereSet& spheres) {
    const std::vector<double> d = union_signed_distance(p.samples[0], spheres);
    return *std::max_element(d.begin(), d.begin() + long(p.weighted[0]));
  };
  auto median = [&](const SphereSet& spheres) {
    std::vector<double> d = union_signed_distance(p.samples[0], spheres);
    d.resize(p.weighted[0]);
    std::nth_element(d.begin(), d.begin() + long(d.size() / 2), d.end());
    return d[d.size() / 2];
  };
  auto radius_at = [&](const Eigen::Vector3d& c) { return query->inside(c) ? query->distance(c) : 0.0; };
  const double step = 0.01 * mesh.diagonal();
  SphereSet kept = start, traded = start;
  EXPECT_GT(refine_off_grid(p.samples[0], p.weighted[0], kept, radius_at, r.delta, step, Log::silent(), true), 0u);
  refine_off_grid(p.samples[0], p.weighted[0], traded, radius_at, r.delta, step);
  // 0.897x here; the refinement that only kept the max left it where it was.
  EXPECT_LT(largest(kept), 0.98 * largest(start));
  EXPECT_LT(median(kept), median(start));
  EXPECT_GT(largest(traded), largest(start)) << "this instance no longer tells the two apart";
  for (const Sphere& s : kept) EXPECT_NEAR(s.radius, query->distance(s.center), 1e-12 * mesh.diagonal());
}

// The refinement over two poses at once (pose-map's joint selection): the car and the car
// sheared, scaled unevenly and moved, each sphere's radius the exact distance in its pose. Moving
// the rest centres lowers the largest vertex error over both poses and the median, no area
// sample leaves delta, every pose's sphere is what spheres_at makes of its centre, and every
// sphere stays inside its pose (brute-force distances to the union, exact distances to the mesh).
TEST(Cover, JointRefinementLowersTheMaxOverEveryPose) {
  std::unique_ptr<MeshQuery> rest_query;
  const TriMesh rest = make_car().rest;
  const CoverProblem p = problem_of(rest, 48, rest_query);
  Eigen::Matrix3d a;
  a << 1.1, 0.2, 0.0, 0.0, 0.8, 0.1, 0.05, 0.0, 1.3;
  const Eigen::Vector3d b(0.4, -0.2, 0.7);
  TriMesh posed = rest;
  for (auto& v : posed.vertices) v = a * v + b;
  const MeshQuery posed_query(posed);
  const std::vector<const MeshQuery*> queries{rest_query.get(), &posed_query};
  const PoseSpheresAt at = [&](const Eigen::Vector3d& c, std::vector<Sphere>& out) {
    out = {{c, 0}, {a * c + b, 0}};
    for (size_t k = 0; k < 2; ++k) {
      if (!queries[k]->inside(out[k].center)) return false;
      out[k].radius = queries[k]->distance(out[k].center);
    }
    return true;
  };
  const std::vector<std::vector<Eigen::Vector3d>> samples{p.samples[0], surface_samples(posed, 700, 2)};
  const std::vector<size_t> weighted{rest.vertices.size(), posed.vertices.size()};
  std::vector<Eigen::Vector3d> centers;
  std::vector<SphereSet> spheres(2);
  for (int c : cover_with_budget(p, 12).chosen) {
    std::vector<Sphere> in;
    if (!at(p.spheres[0][size_t(c)].center, in)) continue;
    centers.push_back(p.spheres[0][size_t(c)].center);
    for (size_t k = 0; k < 2; ++k) spheres[k].push_back(in[k]);
  }
  // Every vertex's error over both poses, and the largest of any sample's.
  auto errors = [&](const std::vector<SphereSet>& s, double& largest_sample) {
    std::vector<double> vertices;
    largest_sample = 0;
    for (size_t k = 0; k < 2; ++k) {
      const std::vector<double> d = union_signed_distance(samples[k], s[k]);
      vertices.insert(vertices.end(), d.begin(), d.begin() + long(weighted[k]));
      largest_sample = std::max(largest_sample, *std::max_element(d.begin(), d.end()));
    }
    std::sort(vertices.begin(), vertices.end());
    return vertices;
  };
  double delta = 0;
  const std::vector<double> before = errors(spheres, delta);
  std::vector<SphereSet> refined = spheres;
  const double step = 0.01 * rest.diagonal();
  EXPECT_GT(refine_jointly(samples, weighted, centers, refined, at, delta, step, Log::silent(), true), 0u);
  double largest_sample = 0;
  const std::vector<double> after = errors(refined, largest_sample);
  EXPECT_LT(after.back(), 0.98 * before.back()) << before.back() << " -> " << after.back();
  EXPECT_LT(after[after.size() / 2], before[before.size() / 2]);
  EXPECT_LE(largest_sample, delta * (1 + 1e-12)) << "a sample left delta";
  for (size_t j = 0; j < centers.size(); ++j) {
    std::vector<Sphere> in;
    ASSERT_TRUE(at(centers[j], in));
    for (size_t k = 0; k < 2; ++k) {
      EXPECT_EQ(refined[k][j].center, in[k].center) << "sphere " << j << " pose " << k;
      EXPECT_EQ(refined[k][j].radius, in[k].radius) << "sphere " << j << " pose " << k;
      EXPECT_TRUE(queries[k]->inside(refined[k][j].center));
      EXPECT_LE(refined[k][j].radius, queries[k]->distance(refined[k][j].center));
    }
  }
}

// The least gap of every sample (the grid search by radius class) is the scan's minimum to the
// bit, over two poses, with spheres of radius 0 (absent) and samples far outside every sphere.
TEST(Cover, LeastGapsMatchAScanOfEveryCandidate) {
  std::unique_ptr<MeshQuery> query;
  const TriMesh mesh = make_barrel().rest;
  CoverProblem p = problem_of(mesh, 48, query);
  std::mt19937 rng(3);
  SphereSet moved = p.spheres[0];
  for (size_t i = 0; i < moved.size(); ++i) {
    moved[i].center += 0.05 * mesh.diagonal() * Eigen::Vector3d::Random();
    if (rng() % 7 == 0) moved[i].radius = 0;
  }
  p.spheres.push_back(moved);
  std::vector<Eigen::Vector3d> far = p.samples[0];
  for (auto& q : far) q = 3 * q + mesh.diagonal() * Eigen::Vector3d::Random();
  p.samples.push_back(far);
  p.weighted.push_back(0);
  const std::vector<double> gaps = least_gaps(p);
  ASSERT_EQ(gaps.size(), p.sample_count());
  size_t n = 0;
  for (size_t k = 0; k < p.samples.size(); ++k)
    for (const Eigen::Vector3d& q : p.samples[k]) {
      double scan = std::numeric_limits<double>::infinity();
      for (const Sphere& s : p.spheres[k])
        if (s.radius > 0) scan = std::min(scan, (q - s.center).norm() - s.radius);
      ASSERT_EQ(gaps[n], scan) << "pose " << k << " sample " << n;
      ++n;
    }
}

// sphere-pack's report says what an independent measurement of its spheres file finds, and
// the budget is never exceeded.
TEST(Cover, SpherePackReportsTheErrorItsFileHas) {
  const std::string dir = test::temp_dir("cover");
  const SampleAsset car = make_car();
  write_file_atomic(dir + "/car.obj", to_obj(car.rest));
  const LoadedMesh mesh = load_mesh(dir + "/car.obj");
  SdfOptions o;
  o.resolution = 64;
  const SdfResult sdf = build_sdf(mesh.mesh, o);
  write_sdf_vdb(dir + "/car.vdb", sdf.field, {{"spx_source_mesh", dir + "/car.obj"}});
  for (size_t budget : {size_t(0), size_t(24)}) {
    SpherePackOptions opt;
    opt.pack.max_spheres = budget;
    json report;
    sphere_pack_files(dir + "/car.vdb", dir + "/car.obj", dir + "/car.spheres.json", opt, Tolerance{}, Log::silent(),
                      report);
    const SpheresFile file = read_spheres_file(dir + "/car.spheres.json");
    const ErrorStats measured = vertex_error(mesh.mesh, file.spheres);
    EXPECT_NEAR(report["cover"]["max_error"].get<double>(), measured.max, 1e-12);
    EXPECT_NEAR(report["cover"]["median_error"].get<double>(), measured.median, 1e-12);
    EXPECT_EQ(report["sphere_count"].get<size_t>(), file.spheres.size());
    EXPECT_LE(report["cover"]["lower_bound"].get<size_t>(), file.spheres.size());
    if (budget > 0) EXPECT_LE(file.spheres.size(), budget);
    if (budget == 0) {  // the default tolerance, met
      EXPECT_TRUE(report["tolerance"]["met"].get<bool>());
      EXPECT_LE(measured.max, kDefaultTolerancePercent / 100 * mesh.mesh.diagonal() * (1 + 1e-12));
    }
    const MeshQuery q(mesh.mesh);
    for (const Sphere& s : file.spheres) EXPECT_LE(s.radius, q.distance(s.center) + 1e-12);
  }
}

// Two poses of `candidates` random spheres in the unit cube, many nearly containing others, some
// absent in one pose, and `samples` random points per pose around them.
CoverProblem two_random_poses(unsigned seed, size_t candidates, size_t samples) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  CoverProblem p;
  p.spheres.resize(2);
  p.samples.resize(2);
  for (size_t c = 0; c < candidates; ++c) {
    const Eigen::Vector3d at(u(rng), u(rng), u(rng));
    const double r = c % 7 == 0 ? 0.0 : 0.02 + 0.2 * u(rng) * u(rng);
    p.spheres[0].push_back({at, r});
    p.spheres[1].push_back({at + 0.01 * Eigen::Vector3d(u(rng), u(rng), u(rng)), c % 11 == 0 ? 0.0 : r * (0.9 + 0.2 * u(rng))});
  }
  for (size_t k = 0; k < 2; ++k)
    for (size_t i = 0; i < samples; ++i) p.samples[k].emplace_back(2 * u(rng) - 0.5, 2 * u(rng) - 0.5, 2 * u(rng) - 0.5);
  return p;
}

// The swaps toward the total error end where no swap lowers it: a second improvement of their
// result swaps nothing. After its first round a slot is tried again only where a swap since may
// have changed what its trial reads; a rule that skipped a slot a swap did change would stop
// short of that (trying no slot after the first round fails here). Several deltas and starts on
// the car's rest and on random problems, each of which ends within the rounds allowed.
TEST(Cover, SwapsEndWhereNoSwapLowersTheTotal) {
  std::unique_ptr<MeshQuery> query;
  const TriMesh mesh = make_car().rest;
  const CoverProblem p = problem_of(mesh, 48, query);
  size_t swapped = 0;
  for (double part : {0.03, 0.045, 0.06, 0.08}) {
    const double delta = part * mesh.diagonal();
    const Coverage cov = coverage_at(p, delta);
    for (bool searched : {false, true}) {
      std::vector<int> once = searched ? smallest_cover(cov, kBudgetSearch, 0, nullptr) : greedy_cover(cov);
      const std::vector<int> start = once;
      improve_cover(p, cov, delta, once.size(), once);
      std::vector<int> twice = once;
      improve_cover(p, cov, delta, twice.size(), twice);
      EXPECT_EQ(twice, once) << part << (searched ? " searched" : " greedy");
      for (size_t k = 0; k < once.size(); ++k) swapped += once[k] != start[k];
    }
  }
  EXPECT_GT(swapped, 20u) << "too few swaps for the test to mean much";
  // And two poses of random spheres (the first 200 samples of each weighted), at several deltas.
  for (unsigned seed = 1; seed <= 40; ++seed) {
    CoverProblem r = two_random_poses(seed, 100 + seed % 5 * 100, 300 + seed % 7 * 100);
    r.weighted = {200, 200};
    for (double delta : {0.03, 0.05, 0.1, 0.15}) {
      const Coverage cov = coverage_at(r, delta);
      std::vector<int> once = greedy_cover(cov);
      improve_cover(r, cov, delta, once.size(), once);
      std::vector<int> twice = once;
      improve_cover(r, cov, delta, twice.size(), twice);
      EXPECT_EQ(twice, once) << "seed " << seed << " delta " << delta;
    }
  }
}

// A swap that moves the error of a sample an option of another slot covers, and none of that
// slot's own: on a line, A (at 0) and B (at 3.5) chosen, C (at 1.2) and B' (at 3.7) not, radii
// 0.5, delta 1. In the first round A for C loses 0.1 (0.2 more at the sample at 0.5, 0.1 less at
// 2.3, which B covers at 0.7), and B for B' gains 0.2 (0.2 less at 4.4 and 4.45, 0.2 more at 2.3).
// After it, the sample at 2.3 is at 0.9, so A for C gains 0.1: the second round must try A again,
// although B and B' share no sample with A, since they do with its option C.
TEST(Cover, SwapsRetryASlotWhoseOptionASwapReached) {
  CoverProblem p;
  p.spheres.push_back({{{0, 0, 0}, 0.5}, {{3.5, 0, 0}, 0.5}, {{1.2, 0, 0}, 0.5}, {{3.7, 0, 0}, 0.5}});
  p.samples.push_back({{0.5, 0, 0}, {2.3, 0, 0}, {4.4, 0, 0}, {4.45, 0, 0}});
  p.weighted.push_back(4);
  const Coverage cov = coverage_at(p, 1.0);
  std::vector<int> chosen = {0, 1};
  improve_cover(p, cov, 1.0, chosen.size(), chosen);
  EXPECT_EQ(chosen, (std::vector<int>{2, 3}));
}

// Representatives against brute force: largest first, a candidate is left out exactly when an
// earlier kept one nearly contains it in both poses (also over several of the blocks whose
// containments are found side by side); and then every sample's gap to some kept candidate is
// within the slack of its gap to the one left out.
std::vector<char> representatives_by_brute_force(const CoverProblem& p, double slack, size_t& left_out) {
  const size_t n_all = p.candidate_count();
  std::vector<size_t> order(n_all);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return p.spheres[0][a].radius > p.spheres[0][b].radius; });
  std::vector<char> want(n_all, 0);
  left_out = 0;
  for (size_t n = 0; n < order.size(); ++n) {
    const size_t a = order[n];
    bool held = false;
    for (size_t m = 0; m < n && !held && p.spheres[0][a].radius > 0; ++m) {
      const size_t b = order[m];
      if (!want[b]) continue;
      bool all = true;
      for (int k = 0; k < 2; ++k) {
        const Sphere &sa = p.spheres[size_t(k)][a], &sb = p.spheres[size_t(k)][b];
        if (sa.radius > 0 && (!(sb.radius > 0) || (sa.center - sb.center).norm() + sa.radius - sb.radius > slack)) all = false;
      }
      held = all;
    }
    want[a] = !held;
    left_out += held;
  }
  return want;
}

TEST(Cover, RepresentativesMatchBruteForce) {
  {
    const CoverProblem large = two_random_poses(6, 5000, 100);
    size_t left_out = 0;
    EXPECT_EQ(representatives(large, 0.03), representatives_by_brute_force(large, 0.03, left_out));
    EXPECT_GT(left_out, 500u) << "too few left out for the test to mean much";
  }
  {
    // Chains: b nearly contains b', b' nearly contains a, b does not (so a stays, b' being left
    // out): in 1 500 groups of three, scaled apart so that their ranks interleave.
    std::mt19937 rng(7);
    CoverProblem chains;
    chains.spheres.emplace_back();
    std::vector<char> want;
    for (int g = 0; g < 1500; ++g) {
      const double s = 1 + 0.2 * double(rng() % 1000) / 1000;
      const Eigen::Vector3d at(10.0 * g, 0, 0), x(s, 0, 0);
      chains.spheres[0].push_back({at, s});
      chains.spheres[0].push_back({at + 0.02 * x, 0.99 * s});
      chains.spheres[0].push_back({at + 0.055 * x, 0.98 * s});
      want.insert(want.end(), {1, 0, 1});
    }
    EXPECT_EQ(representatives(chains, 0.03), want);
  }
  const CoverProblem p = two_random_poses(5, 400, 200);
  const double slack = 0.03;
  const std::vector<char> got = representatives(p, slack);
  size_t left_out = 0;
  const std::vector<char> want = representatives_by_brute_force(p, slack, left_out);
  EXPECT_EQ(got, want);
  EXPECT_GT(left_out, 20u) << "too few left out for the test to mean much";
  for (size_t a = 0; a < 400; ++a) {
    if (got[a]) continue;
    for (int k = 0; k < 2; ++k)
      for (const Eigen::Vector3d& q : p.samples[size_t(k)]) {
        const Sphere& sa = p.spheres[size_t(k)][a];
        if (!(sa.radius > 0)) continue;
        double best = std::numeric_limits<double>::infinity();
        for (size_t b = 0; b < 400; ++b) {
          const Sphere& sb = p.spheres[size_t(k)][b];
          if (got[b] && sb.radius > 0) best = std::min(best, (q - sb.center).norm() - sb.radius);
        }
        ASSERT_LE(best, (q - sa.center).norm() - sa.radius + slack + 1e-12);
      }
  }
}

// The rows gathered in chunks of candidates side by side, with candidates merged into their
// representatives: coverage_at at delta (representatives at merge x delta) and a gap table
// built up to max_delta (representatives at merge x max_delta), at every delta up to it, against
// a scan of every (candidate, sample) pair. 700 candidates: several chunks, the last one short.
TEST(Cover, GapTableAndCoverageMatchAScanOfEveryPair) {
  const size_t n = 700, m = 600;
  CoverProblem p = two_random_poses(17, n, m);
  p.merge = 0.5;
  auto scan = [&](double delta, double merged_at) {
    const std::vector<char> kept = representatives(p, p.merge * merged_at);
    Coverage want;
    want.sample_count = 2 * m;
    want.start.push_back(0);
    for (size_t c = 0; c < n; ++c) {
      for (size_t k = 0; k < 2 && kept[c]; ++k)
        for (size_t i = 0; i < m; ++i) {
          const Sphere& s = p.spheres[k][c];
          if (s.radius > 0 && (p.samples[k][i] - s.center).norm() - s.radius <= delta) want.samples.push_back(uint32_t(k * m + i));
        }
      want.start.push_back(uint32_t(want.samples.size()));
    }
    return want;
  };
  auto expect_same = [](const Coverage& got, const Coverage& want, const std::string& what) {
    EXPECT_EQ(got.sample_count, want.sample_count) << what;
    EXPECT_EQ(got.start, want.start) << what;
    EXPECT_EQ(got.samples, want.samples) << what;
  };
  const double max_delta = 0.12;
  const GapTable table(p, max_delta);
  for (double delta : {0.0, 0.01, 0.05, 0.08, max_delta, 0.2}) {
    expect_same(coverage_at(p, delta), scan(delta, delta), "coverage_at " + std::to_string(delta));
    expect_same(table.at(delta), scan(std::min(delta, max_delta), max_delta), "table at " + std::to_string(delta));
  }
  const Coverage some = table.at(max_delta);
  EXPECT_GT(some.samples.size(), 1000u) << "too few pairs for the test to mean much";
  // Shrunk, the table keeps the representatives of its first max_delta.
  GapTable shrunk(p, max_delta);
  shrunk.shrink(0.06);
  for (double delta : {0.0, 0.01, 0.05, 0.06})
    expect_same(shrunk.at(delta), scan(delta, max_delta), "shrunk table at " + std::to_string(delta));
  const std::vector<char> kept = representatives(p, p.merge * max_delta);
  EXPECT_LT(std::count(kept.begin(), kept.end(), 1), std::ptrdiff_t(n - 50)) << "too few merged for the test to mean much";
}

// Every pair of `p` within `max_delta`, by candidate then sample, and the coverage a scan of
// their exact gaps gives at a delta.
struct GapPairs {
  struct Pair {
    uint32_t candidate, sample;
    double gap;
  };
  GapPairs(const CoverProblem& p, double max_delta) : candidates(p.candidate_count()), samples(p.sample_count()) {
    for (size_t c = 0; c < candidates; ++c)
      for (size_t k = 0, first = 0; k < p.samples.size(); first += p.samples[k++].size())
        for (size_t i = 0; i < p.samples[k].size(); ++i) {
          const Sphere& s = p.spheres[k][c];
          const double gap = (p.samples[k][i] - s.center).norm() - s.radius;
          if (s.radius > 0 && gap <= max_delta) pairs.push_back({uint32_t(c), uint32_t(first + i), gap});
        }
  }
  Coverage scan(double delta) const {
    Coverage want;
    want.sample_count = samples;
    want.start.assign(candidates + 1, 0);
    for (const Pair& q : pairs)
      if (q.gap <= delta) {
        want.samples.push_back(q.sample);
        ++want.start[q.candidate + 1];
      }
    for (size_t c = 0; c < candidates; ++c) want.start[c + 1] += want.start[c];
    return want;
  }
  size_t candidates, samples;
  std::vector<Pair> pairs;
};

// At a pair's own gap, and one step of a double below and above it, the table and coverage_at
// give exactly the pairs a scan of the exact gaps gives; with `shrunk_to`, the table built up
// to max_delta then shrunk to it, asked below it. Returns how many deltas were asked.
size_t expect_table_exact_at_pair_gaps(const CoverProblem& p, const GapPairs& all, double max_delta,
                                       double shrunk_to = 0) {
  GapTable table(p, max_delta);
  if (shrunk_to > 0) table.shrink(shrunk_to);
  const double asked_up_to = shrunk_to > 0 ? shrunk_to : max_delta;
  std::vector<double> gaps;
  for (size_t q = 0; q < all.pairs.size(); q += all.pairs.size() / 40) gaps.push_back(all.pairs[q].gap);
  if (shrunk_to > 0) gaps.push_back(shrunk_to);
  size_t asked = 0;
  for (double g : gaps) {
    for (double delta : {g, std::nextafter(g, -1.0), std::nextafter(g, 1.0)}) {
      if (delta > asked_up_to) continue;
      const Coverage want = all.scan(delta), got = table.at(delta), direct = coverage_at(p, delta);
      EXPECT_EQ(got.start, want.start) << "table at " << delta;
      EXPECT_EQ(got.samples, want.samples) << "table at " << delta;
      EXPECT_EQ(direct.start, want.start) << "coverage_at " << delta;
      EXPECT_EQ(direct.samples, want.samples) << "coverage_at " << delta;
      ++asked;
    }
  }
  return asked;
}

// The table keeps each gap's bucket (as many bits as the samples' indices leave) and asks the
// geometry where a gap's bucket is delta's: small spheres among many samples (rows put in order
// by a sort) and large ones (by a bitmap), and 1.2 million samples (11-bit buckets, more pairs in
// delta's).
TEST(Cover, GapTableDecidesTheGapsAtDeltaExactly) {
  const size_t n = 300, m = 20000;
  const CoverProblem p = two_random_poses(23, n, m);
  const double max_delta = 0.08;
  const GapPairs all(p, max_delta);
  // Rows of both kinds: a few samples among a pose's 20 000, and a hundred or more.
  const Coverage every = all.scan(max_delta);
  size_t few = 0, many = 0;
  for (size_t c = 0; c < n; ++c) {
    const uint32_t size = every.start[c + 1] - every.start[c];
    few += size > 0 && size < 20;
    many += size > 100;
  }
  EXPECT_GT(few, 10u);
  EXPECT_GT(many, 10u);
  EXPECT_GT(expect_table_exact_at_pair_gaps(p, all, max_delta), 100u);
  // Shrunk to a pair's own gap, so that the pairs of its bucket lie on both sides of the edge.
  const double shrunk_to = all.pairs[all.pairs.size() / 2].gap;
  EXPECT_GT(expect_table_exact_at_pair_gaps(p, all, max_delta, shrunk_to), 40u);

  const CoverProblem dense = two_random_poses(29, 12, 600000);
  const GapPairs dense_pairs(dense, max_delta);
  EXPECT_GT(expect_table_exact_at_pair_gaps(dense, dense_pairs, max_delta), 100u);
  EXPECT_GT(expect_table_exact_at_pair_gaps(dense, dense_pairs, max_delta, dense_pairs.pairs[dense_pairs.pairs.size() / 2].gap),
            40u);
}

// Brute force over every triangle: the distance from p to the mesh, and whether p is inside
// (winding number from the triangles' solid angles, van Oosterom and Strackee).
double brute_distance(const TriMesh& mesh, const Eigen::Vector3d& p) {
  double best = std::numeric_limits<double>::infinity();
  for (const auto& t : mesh.triangles)
    best = std::min(best, (closest_point_on_triangle(p, mesh.vertices[size_t(t[0])], mesh.vertices[size_t(t[1])],
                                                     mesh.vertices[size_t(t[2])]) - p).norm());
  return best;
}
bool brute_inside(const TriMesh& mesh, const Eigen::Vector3d& p) {
  double angle = 0;
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d a = mesh.vertices[size_t(t[0])] - p, b = mesh.vertices[size_t(t[1])] - p,
                          c = mesh.vertices[size_t(t[2])] - p;
    const double la = a.norm(), lb = b.norm(), lc = c.norm();
    angle += 2 * std::atan2(a.dot(b.cross(c)), la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb);
  }
  return angle / (4 * M_PI) > 0.5;
}

// Every sample has a candidate that passes through it (within kTouchSlack of the diagonal:
// float rounding), whatever the field's resolution; every candidate is inscribed (center inside
// and radius at most the distance to every triangle). On the car (flat panels meeting at sharp
// edges and corners) and the barrel (curved), with a coarse field.
TEST(Candidates, EverySampleIsReachedByItsOwnInscribedCandidate) {
  for (const TriMesh& mesh : {make_car().rest, make_barrel().rest}) {
    SdfOptions o;
    o.resolution = 24;
    const SdfResult sdf = build_sdf(mesh, o);
    const MeshQuery query(mesh);
    const SurfaceSamples samples = sample_surface(mesh, 300, 1);
    const TangentCandidates t = tangent_candidates(query, mesh, samples, sdf.field, deepest_radius(sdf.field), {});
    EXPECT_EQ(t.unreached, 0u);
    const double diag = mesh.diagonal();
    for (const Sphere& s : t.spheres) {
      ASSERT_TRUE(brute_inside(mesh, s.center)) << s.center.transpose();
      ASSERT_LE(s.radius, brute_distance(mesh, s.center) * (1 + 1e-9)) << s.center.transpose();
    }
    for (size_t i = 0; i < samples.points.size(); ++i) {
      double gap = std::numeric_limits<double>::infinity();
      for (const Sphere& s : t.spheres) gap = std::min(gap, (samples.points[i] - s.center).norm() - s.radius);
      ASSERT_LE(gap, kTouchSlack * diag * (1 + 1e-6)) << "sample " << i << " at " << samples.points[i].transpose();
    }
  }
}

// A sample's rest ("car" or "barrel") and its field at `resolution` cells.
std::pair<TriMesh, SdfResult> sample_with_field(const std::string& name, int resolution) {
  TriMesh mesh = make_sample(name).rest;
  SdfOptions o;
  o.resolution = resolution;
  SdfResult sdf = build_sdf(mesh, o);
  return {std::move(mesh), std::move(sdf)};
}

// Balls through a few samples alone are those the whole set gives them, each naming the sample
// it touches; the balls nested in one touch the same point, are inscribed (brute force), and
// halve down to the first at most the least asked; and the balls around it are inscribed and
// reach it within the distance asked.
TEST(Candidates, BallsThroughChosenSamplesAndNestedOnes) {
  const auto [mesh, sdf] = sample_with_field("barrel", 24);
  const MeshQuery query(mesh);
  const SurfaceSamples samples = sample_surface(mesh, 300, 1);
  const double start = deepest_radius(sdf.field);
  const TangentCandidates all = tangent_candidates(query, mesh, samples, sdf.field, start, {});
  ASSERT_EQ(all.touches.size(), all.spheres.size());
  std::vector<uint32_t> which;
  for (uint32_t i = 3; i < samples.points.size(); i += 37) which.push_back(i);
  const TangentCandidates some = tangent_candidates(query, mesh, samples, which, nullptr, start, {});
  size_t expected = 0;
  for (size_t n = 0; n < all.spheres.size(); ++n) {
    if (!std::binary_search(which.begin(), which.end(), all.touches[n])) continue;
    ASSERT_LT(expected, some.spheres.size());
    EXPECT_EQ(some.touches[expected], all.touches[n]);
    EXPECT_EQ(some.spheres[expected].center, all.spheres[n].center);
    EXPECT_EQ(some.spheres[expected].radius, all.spheres[n].radius);
    ++expected;
  }
  EXPECT_EQ(expected, some.spheres.size());
  const double within = 0.02 * mesh.diagonal(), least = 0.5 * within;
  const SphereSet nested = balls_through(query, samples, which, nullptr, start, {}, least);
  EXPECT_GT(nested.size(), some.spheres.size()) << "each ball and smaller ones in it";
  const SphereSet around_all = balls_around_samples(query, samples, which, nullptr, start, {}, within);
  size_t at = 0;
  for (size_t n = 0; n < some.spheres.size(); ++n) {
    const Eigen::Vector3d& p = samples.points[some.touches[n]];
    const std::vector<Sphere> inner = nested_balls(query, p, some.spheres[n], least);
    const bool second = n > 0 && some.touches[n - 1] == some.touches[n];
    const std::vector<Sphere> around =
        second ? std::vector<Sphere>{} : balls_around(query, p, some.spheres[n].center - p, within);
    if (!second) EXPECT_GE(around.size(), 1u) << "at least the one along the ball's axis, half the distance in";
    for (const Sphere& s : around) {
      ASSERT_TRUE(brute_inside(mesh, s.center)) << s.center.transpose();
      EXPECT_NEAR(s.radius, brute_distance(mesh, s.center), 1e-9 * mesh.diagonal());
      EXPECT_LE((p - s.center).norm(), 0.95 * within * (1 + 1e-12)) << "it reaches the point within the distance";
      ASSERT_LT(at, around_all.size());
      EXPECT_EQ(around_all[at].center, s.center);
      EXPECT_EQ(around_all[at].radius, s.radius);
      ++at;
    }
    ASSERT_FALSE(inner.empty());
    double last = some.spheres[n].radius;
    for (const Sphere& s : inner) {
      ASSERT_TRUE(brute_inside(mesh, s.center)) << s.center.transpose();
      EXPECT_NEAR(s.radius, brute_distance(mesh, s.center), 1e-9 * mesh.diagonal());
      EXPECT_LE((p - s.center).norm() - s.radius, (p - some.spheres[n].center).norm() - some.spheres[n].radius +
                                                       1e-9 * mesh.diagonal()) << "it reaches the point as the ball does";
      EXPECT_LT(s.radius, last);
      last = s.radius;
    }
    EXPECT_LE(inner.back().radius, least);
    if (inner.size() > 1) EXPECT_GT(inner[inner.size() - 2].radius, least);
  }
  EXPECT_EQ(at, around_all.size()) << "balls_around_samples: each sample's balls around, in order";
}

// The shrinking ball against brute force: on a slab 0.02 thick and on a sphere of flat faces,
// the offset of the ball tangent at a face's middle is the largest t whose ball at p + t n
// holds no point of a triangle other than the face's own neighbours (bisected over every
// triangle), and the radius is the distance from its center.
TEST(Candidates, TangentBallIsTheLargestThatFits) {
  for (const TriMesh& mesh : {test::box_mesh({0, 0, 0}, {1, 1, 0.02}), test::uv_sphere(1, 24, 48)}) {
    const MeshQuery query(mesh);
    for (size_t face = 0; face < mesh.triangles.size(); face += 97) {
      const Eigen::Vector3i& f = mesh.triangles[face];
      const std::vector<Eigen::Vector3d> own = {mesh.vertices[size_t(f[0])], mesh.vertices[size_t(f[1])],
                                                mesh.vertices[size_t(f[2])]};
      const Eigen::Vector3d p = (own[0] + own[1] + own[2]) / 3, n = -(own[1] - own[0]).cross(own[2] - own[0]).normalized();
      auto fits = [&](double t) {
        for (const auto& g : mesh.triangles) {
          const Eigen::Vector3d a = mesh.vertices[size_t(g[0])], b = mesh.vertices[size_t(g[1])], c = mesh.vertices[size_t(g[2])];
          if (std::any_of(own.begin(), own.end(), [&](const Eigen::Vector3d& k) { return k == a || k == b || k == c; })) continue;
          if ((closest_point_on_triangle(p + t * n, a, b, c) - p - t * n).norm() < t) return false;
        }
        return true;
      };
      double lo = 0, hi = 10;
      for (int step = 0; step < 60; ++step) (fits(0.5 * (lo + hi)) ? lo : hi) = 0.5 * (lo + hi);
      const Sphere s = tangent_ball(query, p, n, own, 10, 1e-9);
      EXPECT_NEAR((s.center - p).norm(), lo, 1e-6 * lo) << "face " << face;
      EXPECT_NEAR(s.radius, brute_distance(mesh, s.center), 1e-12);
    }
  }
  const Sphere s = tangent_ball(MeshQuery(test::box_mesh({0, 0, 0}, {1, 1, 0.02})), {0.5, 0.4, 0}, {0, 0, 1},
                                {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}}, 10, 1e-9);
  EXPECT_NEAR(s.radius, 0.01, 1e-12);
}

// A tolerance finer than the field's voxels: the voxels' candidates cannot reach some samples
// (the report would name a finer resolution); with the tangent candidates the cover meets it,
// and the max vertex error measured independently is within it, with no sphere past the surface.
TEST(Candidates, ToleranceFinerThanTheFieldIsMet) {
  const auto [mesh, sdf] = sample_with_field("barrel", 10);
  const MeshQuery query(mesh);
  SpherePackOptions opt;
  opt.tolerance = 0.004 * mesh.diagonal();
  opt.area_samples = 500;
  opt.tangent_candidates = false;
  const CoverSelection voxels = select_by_cover(sdf.field, query, opt);
  EXPECT_GT(voxels.cover.uncoverable(), 0u) << "the field alone should fall short here";
  opt.tangent_candidates = true;
  const CoverSelection both = select_by_cover(sdf.field, query, opt);
  EXPECT_EQ(both.cover.uncoverable(), 0u);
  EXPECT_GT(both.chosen_tangent, 0u);
  EXPECT_LE(vertex_error(mesh, both.spheres).max, opt.tolerance * (1 + 1e-9));
  for (const Sphere& s : both.spheres) {
    EXPECT_TRUE(brute_inside(mesh, s.center));
    EXPECT_LE(s.radius, brute_distance(mesh, s.center) * (1 + 1e-9));
  }
}

// A tolerance out of reach of every candidate (the open cylinder at 1 %: across its holes every
// radius is the field's bound): the samples out of reach are still covered, as near as the
// candidates come, so that no vertex is farther than the least delta that reaches them all. A
// cover that left them bare left the max at 2.2x that (0.0965 against 0.0431).
TEST(Cover, SamplesOutOfReachAreCoveredAsNearAsTheCandidatesCome) {
  SPX_REQUIRE_SHARED_DATA();
  const TriMesh mesh = load_mesh(test::shared_data() + "/cylinder/rest.obj").mesh;
  const MeshQuery query(mesh);
  SdfOptions sdf_options;
  sdf_options.resolution = 128;
  const SdfResult sdf = build_sdf(mesh, sdf_options);
  SpherePackOptions opt;
  opt.pack.field_bounds_radius = sdf.stats.bounded_by_holes;
  opt.tolerance = 0.01 * mesh.diagonal();
  const CoverSelection sel = select_by_cover(sdf.field, query, opt);
  ASSERT_EQ(sel.limited_by, Limit::resolution);
  ASSERT_GT(sel.cover.uncoverable(), 0u);
  EXPECT_GT(sel.cover.least_reachable, opt.tolerance);
  EXPECT_GT(sel.out_of_reach_added, 0u);
  EXPECT_LE(vertex_error(query.surface(), sel.spheres).max, sel.cover.least_reachable * (1 + 1e-9));
}

// A medial sheet's voxels grow with the square of the resolution, and so must its candidates:
// nothing thins them back to a fixed count that would undo a finer field.
TEST(Candidates, FinerFieldOffersFinerCandidates) {
  const TriMesh slab = test::box_mesh({0, 0, 0}, {1, 1, 0.1});
  const MeshQuery query(slab);
  auto count_at = [&](int resolution) {
    SdfOptions o;
    o.resolution = resolution;
    return inscribed_candidates(build_sdf(slab, o).field, query, {}).size();
  };
  const size_t coarse = count_at(64), fine = count_at(160);
  EXPECT_GT(fine, 12000u);
  EXPECT_GT(double(fine), 5.0 * double(coarse)) << coarse << " at 64 cells, " << fine << " at 160";
}

// The polish (sphere-pack's budget mode): the set kept has a max vertex error no higher than the
// first refinement's and a lower product of max and median (on this instance a polished set is
// kept), at most the budget, every sphere inside at its exact distance, every sample within the
// delta of the cover kept with it, and some of that cover's spheres an earlier refinement's.
TEST(Cover, PolishKeepsABetterSetInside) {
  const auto [mesh, sdf] = sample_with_field("car", 48);
  const MeshQuery query(mesh);
  SpherePackOptions opt;
  opt.pack.max_spheres = 10;
  opt.area_samples = 1000;
  opt.polish_rounds = 0;
  const CoverSelection plain = select_by_cover(sdf.field, query, opt);
  opt.polish_rounds = 3;
  const CoverSelection polished = select_by_cover(sdf.field, query, opt);
  // The vertices' median and max as the polish weighs them (the middle one, not interpolated).
  auto stats = [&](const SphereSet& spheres) {
    return detail::median_and_max_of(union_signed_distance(query.surface().vertices, spheres));
  };
  const auto [median_before, max_before] = stats(plain.spheres);
  const auto [median_after, max_after] = stats(polished.spheres);
  EXPECT_GT(polished.polished, 0u) << "no round was kept on this instance";
  EXPECT_LE(max_after, max_before);
  EXPECT_LT(max_after * median_after, max_before * median_before);
  EXPECT_LE(polished.spheres.size(), opt.pack.max_spheres);
  EXPECT_LE(polished.chosen_tangent + polished.chosen_refined, polished.spheres.size());
  EXPECT_GT(polished.chosen_refined, 0u) << "the kept cover chose none of the refined spheres";
  for (const Sphere& s : polished.spheres) {
    EXPECT_TRUE(brute_inside(mesh, s.center));
    EXPECT_NEAR(s.radius, brute_distance(mesh, s.center), 1e-12 * mesh.diagonal());
  }
  const SurfaceSamples samples = sample_surface(query.surface(), opt.area_samples, opt.seed);
  for (double v : union_signed_distance(samples.points, polished.spheres))
    EXPECT_LE(v, polished.cover.delta * (1 + 1e-9));
}

}  // namespace
}  // namespace spx

namespace spx {
namespace {

// spaced_points against a scan of every pair: every point of the first `count` within the
// spacing of a kept one, no two kept ones that close, the kept ones the first of their
// neighbourhoods (in order).
TEST(Candidates, SpacedPointsAgainstAScanOfEveryPair) {
  std::mt19937 rng(31);
  std::uniform_real_distribution<double> u(0, 1);
  for (int trial = 0; trial < 20; ++trial) {
    std::vector<Eigen::Vector3d> points(200 + rng() % 1500);
    for (auto& p : points) p = {u(rng), 2 * u(rng), trial % 4 == 0 ? 0.0 : 0.5 * u(rng)};
    const size_t count = points.size() - rng() % 100;
    const double spacing = 0.02 + 0.2 * u(rng);
    const std::vector<uint32_t> kept = spaced_points(points, count, spacing);
    ASSERT_TRUE(std::is_sorted(kept.begin(), kept.end()));
    std::vector<char> is_kept(points.size(), 0);
    for (uint32_t k : kept) {
      ASSERT_LT(k, count);
      is_kept[k] = 1;
    }
    for (size_t i = 0; i < count; ++i) {
      bool near_earlier_kept = false, near_kept = false;
      for (uint32_t k : kept) {
        const bool near = (points[k] - points[i]).norm() <= spacing;
        near_kept |= near;
        near_earlier_kept |= near && k < i;
      }
      ASSERT_TRUE(near_kept) << "trial " << trial << ", point " << i;
      ASSERT_EQ(bool(is_kept[i]), !near_earlier_kept) << "trial " << trial << ", point " << i;
    }
  }
}

// The barrel split 64-fold (43 000 vertices), and its field at 48 cells.
std::pair<TriMesh, SdfResult> dense_barrel() {
  TriMesh mesh = split_at_midpoints(make_barrel().rest, 3);
  SdfOptions o;
  o.resolution = 48;
  SdfResult sdf = build_sdf(mesh, o);
  return {std::move(mesh), std::move(sdf)};
}

// A tolerance far above the spacing of the vertices (8 % on the barrel split 64-fold, as a scan
// or a subdivided sculpt is): the cover is solved on vertices an eighth of the tolerance apart, and
// the vertices its first cover leaves past the tolerance (on this instance some) join until none
// is. Every vertex and area sample within the tolerance, every sphere inside.
TEST(Cover, SpacedCoverLeavesNoVertexPastTheTolerance) {
  const auto [mesh, sdf] = dense_barrel();
  const MeshQuery query(mesh);
  SpherePackOptions opt;
  opt.tolerance = 0.08 * mesh.diagonal();
  opt.area_samples = 500;
  const CoverSelection sel = select_by_cover(sdf.field, query, opt);
  EXPECT_LT(sel.cover_samples, sel.samples / 2) << "the vertices were not spaced";
  EXPECT_GT(sel.spaced_joined, 0u) << "the first cover left no vertex bare on this instance";
  EXPECT_EQ(sel.limited_by, Limit::tolerance);
  EXPECT_LE(vertex_error(mesh, sel.spheres).max, opt.tolerance * (1 + 1e-9));
  const SurfaceSamples samples = sample_surface(mesh, opt.area_samples, opt.seed);
  for (double v : union_signed_distance(samples.points, sel.spheres)) ASSERT_LE(v, opt.tolerance * (1 + 1e-9));
  for (const Sphere& s : sel.spheres) {
    EXPECT_TRUE(brute_inside(mesh, s.center));
    EXPECT_LE(s.radius, brute_distance(mesh, s.center) * (1 + 1e-9));
  }
}

// Budget mode on the same dense barrel: the vertices are spaced an eighth of the area samples'
// delta apart, those the cover leaves past its delta join once, and the refinement weighs every
// vertex. The cover's spheres leave no vertex farther than its delta and the spacing (each lies
// within the spacing of a covered one), and the refinement, whose max descent weighs every
// vertex, leaves none farther than they did. At most the budget, every sphere inside.
TEST(Cover, SpacedBudgetCoverBoundsEveryVertex) {
  const auto [mesh, sdf] = dense_barrel();
  const MeshQuery query(mesh);
  SpherePackOptions opt;
  opt.pack.max_spheres = 8;
  opt.area_samples = 300;
  opt.polish_rounds = 0;
  const CoverSelection sel = select_by_cover(sdf.field, query, opt);
  ASSERT_LT(sel.cover_samples, sel.samples / 2) << "the vertices were not spaced";
  ASSERT_GT(sel.vertex_spacing, 0);
  SphereSet covered;  // the cover's spheres before the refinement
  for (int c : sel.cover.chosen) covered.push_back(sel.offered[size_t(c)]);
  const double max = vertex_error(mesh, sel.spheres).max, before = vertex_error(mesh, covered).max;
  EXPECT_LE(before, (sel.cover.delta + sel.vertex_spacing) * (1 + 1e-9));
  EXPECT_LE(max, before * (1 + 1e-9)) << "the refinement raised some vertex's error past the cover's max";
  EXPECT_LE(sel.spheres.size(), opt.pack.max_spheres);
  for (const Sphere& s : sel.spheres) {
    EXPECT_TRUE(brute_inside(mesh, s.center));
    EXPECT_LE(s.radius, brute_distance(mesh, s.center) * (1 + 1e-9));
  }
}

void expect_same_spheres(const CoverSelection& a, const CoverSelection& b, const std::string& what) {
  ASSERT_EQ(a.spheres.size(), b.spheres.size()) << what;
  for (size_t s = 0; s < a.spheres.size(); ++s) {
    EXPECT_EQ(a.spheres[s].center, b.spheres[s].center) << what << ", sphere " << s;
    EXPECT_EQ(a.spheres[s].radius, b.spheres[s].radius) << what << ", sphere " << s;
  }
  EXPECT_EQ(a.cover.chosen, b.cover.chosen) << what;
}

// sphere-pack --cache: a run at one tolerance keeps the voxel candidates and the samples' balls;
// runs at another tolerance and at a budget read them and choose the spheres a run without the
// cache chooses, to the bit. A file cut short is taken as empty and written whole again; another
// field has a file of its own.
TEST(Cover, CandidateCacheChoosesAsWithoutIt) {
  const auto [mesh, sdf] = sample_with_field("car", 48);
  const MeshQuery query(mesh);
  const std::string dir = test::temp_dir("candidate-cache") + "/made";  // made by the run
  SpherePackOptions coarse;
  coarse.tolerance = 0.05 * mesh.diagonal();
  coarse.area_samples = 1000;
  SpherePackOptions fine = coarse;
  fine.tolerance = 0.02 * mesh.diagonal();
  SpherePackOptions budget = coarse;
  budget.tolerance = 0;
  budget.pack.max_spheres = 10;
  const auto cached = [&](SpherePackOptions opt) {
    opt.cache_dir = dir;
    return select_by_cover(sdf.field, query, opt);
  };
  const CoverSelection first = cached(coarse);
  ASSERT_TRUE(first.cache.has_value());
  EXPECT_FALSE(first.cache->voxels_read);
  EXPECT_EQ(first.cache->balls_read, 0u);
  EXPECT_EQ(first.cache->balls_made, first.samples);
  EXPECT_FALSE(select_by_cover(sdf.field, query, coarse).cache.has_value());
  expect_same_spheres(select_by_cover(sdf.field, query, coarse), first, "the first tolerance");
  const CoverSelection finer = cached(fine);
  EXPECT_TRUE(finer.cache->voxels_read);
  EXPECT_EQ(finer.cache->balls_read, finer.samples);
  EXPECT_EQ(finer.cache->balls_made, 0u);
  const CoverSelection fine_plain = select_by_cover(sdf.field, query, fine);
  expect_same_spheres(fine_plain, finer, "another tolerance");
  expect_same_spheres(select_by_cover(sdf.field, query, budget), cached(budget), "a budget");

  const std::string file = finer.cache->file;
  const std::string whole = read_file(file);
  write_file_atomic(file, whole.substr(0, whole.size() / 2));
  const CoverSelection cut = cached(fine);
  EXPECT_FALSE(cut.cache->voxels_read);
  EXPECT_EQ(cut.cache->balls_read, 0u);
  expect_same_spheres(fine_plain, cut, "a cache cut short");
  EXPECT_EQ(read_file(file), whole);

  SpherePackOptions elsewhere = coarse;
  elsewhere.cache_dir = dir;
  const CoverSelection other_field = select_by_cover(sample_with_field("car", 40).second.field, query, elsewhere);
  EXPECT_NE(other_field.cache->file, file);
  EXPECT_FALSE(other_field.cache->voxels_read);
}

// The cache's balls of any subset of the samples are those tangent_balls makes; it asks only for
// the samples it lacks (a spaced cover asks some, a later run more), and a cache read back from
// its file lacks none of them.
TEST(Candidates, CacheAsksOnlyForTheBallsItLacks) {
  const auto [mesh, sdf] = sample_with_field("car", 32);
  const MeshQuery query(mesh);
  const SurfaceSamples samples = sample_surface(mesh, 200, 1);
  const CandidateOptions limits;
  const std::string dir = test::temp_dir("candidate-cache-balls");
  std::vector<uint32_t> asked;
  const auto make = [&](const std::vector<uint32_t>& which) {
    asked = which;
    return tangent_balls(query, mesh, samples, which, &sdf.field, deepest_radius(sdf.field), limits);
  };
  std::vector<uint32_t> even, first_hundred(100), later;
  std::iota(first_hundred.begin(), first_hundred.end(), 0u);
  for (uint32_t i = 0; i < 100; i += 2) even.push_back(i);
  for (uint32_t i = 100; i < 150; ++i) later.push_back(i);
  const std::vector<SampleBalls> truth = make(first_hundred);
  {
    CandidateCache cache(dir, sdf.field, mesh, samples, limits);
    cache.tangent_balls(even, make);
    EXPECT_EQ(asked, even);
    const std::vector<SampleBalls> got = cache.tangent_balls(first_hundred, make);
    std::vector<uint32_t> odd;
    for (uint32_t i = 1; i < 100; i += 2) odd.push_back(i);
    EXPECT_EQ(asked, odd);
    for (size_t i = 0; i < 100; ++i)
      for (int k = 0; k < 2; ++k) {
        EXPECT_EQ(got[i][size_t(k)].center, truth[i][size_t(k)].center) << i;
        EXPECT_EQ(got[i][size_t(k)].radius, truth[i][size_t(k)].radius) << i;
      }
    EXPECT_EQ(cache.save(), "");
  }
  CandidateCache back(dir, sdf.field, mesh, samples, limits);
  asked = {42};
  back.tangent_balls(first_hundred, make);
  EXPECT_EQ(asked, std::vector<uint32_t>{42}) << "a sample saved was asked again";
  EXPECT_EQ(back.balls_read(), 100u);
  back.tangent_balls(later, make);
  EXPECT_EQ(asked, later);
}

}  // namespace
}  // namespace spx
