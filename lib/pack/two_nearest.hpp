#pragma once
// pack internals: a sample's two nearest spheres (the centre refinement's ranking), in full and
// after one sphere moved.
#include <cstddef>

namespace spx::detail {

// The two nearest of some spheres to one sample: the least two by (gap, index); -1 where fewer.
struct TwoNearest {
  int first = -1, second = -1;
};

// Over spheres 0..n-1, gap(j) each one's.
template <class Gap>
TwoNearest two_nearest(size_t n, const Gap& gap) {
  TwoNearest out;
  double ga = 0, gb = 0;
  for (size_t j = 0; j < n; ++j) {
    const double g = gap(j);
    if (out.first < 0 || g < ga) {
      out.second = out.first, gb = ga;
      out.first = int(j), ga = g;
    } else if (out.second < 0 || g < gb) {
      out.second = int(j), gb = g;
    }
  }
  return out;
}

// The same after sphere `moved` alone moved (its gap was `old_gap`; gap(j) is each one's now),
// given the two before. Where the moved one was neither, the two are the least two of them and
// it; where it was one and came no farther, the same two in some order; only where it went
// farther may a third overtake it, and every sphere is asked again.
template <class Gap>
TwoNearest two_nearest_after_move(TwoNearest was, size_t moved, double old_gap, size_t n, const Gap& gap) {
  const int m = int(moved);
  if (was.second < 0) return two_nearest(n, gap);
  auto before = [](double x, int a, double y, int b) { return x < y || (x == y && a < b); };
  const double g = gap(moved);
  if (was.first == m || was.second == m) {
    if (g > old_gap) return two_nearest(n, gap);
    const int other = was.first == m ? was.second : was.first;
    return before(g, m, gap(size_t(other)), other) ? TwoNearest{m, other} : TwoNearest{other, m};
  }
  if (before(g, m, gap(size_t(was.first)), was.first)) return {m, was.first};
  if (before(g, m, gap(size_t(was.second)), was.second)) return {was.first, m};
  return was;
}

}  // namespace spx::detail
