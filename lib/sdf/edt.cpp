#include "sdf/edt.hpp"

#include <algorithm>
#include <limits>
#include <type_traits>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace spx {
namespace {

// Squared distances in voxels: 32 bits while they fit (half the memory traffic), else 64.
template <class Dist>
constexpr Dist kNone = std::numeric_limits<Dist>::max() / 4;

// 1D squared-distance transform of f (kNone = no sample), its argmin only, on a line of n samples.
template <class Dist>
struct LineScratch {
  std::vector<Dist> f;
  std::vector<int32_t> arg, feat, v;
  explicit LineScratch(int n) : f(n), arg(n), feat(n), v(n) {}
};

// The lower envelope of the parabolas (x - p)^2 + f[p] (Felzenszwalb & Huttenlocher), compared
// in integers: the parabolas from p < q meet at (F(q) - F(p)) / 2(q - p), F(p) = f[p] + p^2, and
// each comparison of two such points is cross-multiplied instead of divided (exact, and no
// division in the loop).
template <class Dist>
void transform_line(int n, LineScratch<Dist>& s) {
  using Wide = std::conditional_t<sizeof(Dist) == 4, int64_t, __int128>;
  auto F = [&](int p) { return Wide(s.f[p]) + Wide(p) * p; };
  int k = -1;
  for (int q = 0; q < n; ++q) {
    if (s.f[q] >= kNone<Dist>) continue;
    // v[k] is hidden when q's parabola meets it no later than v[k - 1]'s does.
    while (k > 0) {
      const int p = s.v[k], r = s.v[k - 1];
      if ((F(q) - F(p)) * (p - r) > (F(p) - F(r)) * (q - p)) break;
      --k;
    }
    s.v[++k] = q;
  }
  if (k < 0) {
    std::fill(s.arg.begin(), s.arg.begin() + n, -1);
    return;
  }
  for (int q = 0, m = 0; q < n; ++q) {
    // On to the next parabola while it meets this one before q.
    while (m < k && F(s.v[m + 1]) - F(s.v[m]) < Wide(2) * q * (s.v[m + 1] - s.v[m])) ++m;
    s.arg[q] = s.v[m];
  }
}

template <class Dist>
GridVector<int32_t> transform(const GridShape& shape, const uint8_t* seed, uint8_t bits) {
  const int nx = shape.dims.x(), ny = shape.dims.y(), nz = shape.dims.z();
  GridVector<int32_t> feature(shape.count());

  // Pass along z (contiguous): nearest seed on the line by two scans.
  tbb::parallel_for(tbb::blocked_range<int>(0, nx * ny), [&](const tbb::blocked_range<int>& r) {
    for (int line = r.begin(); line != r.end(); ++line) {
      const size_t base = size_t(line) * nz;
      int last = -1;
      for (int k = 0; k < nz; ++k) {
        if (seed[base + k] & bits) last = k;
        feature[base + k] = last;
      }
      last = -1;
      for (int k = nz - 1; k >= 0; --k) {
        if (seed[base + k] & bits) last = k;
        const int before = feature[base + k];
        int best = before;
        if (last >= 0 && (before < 0 || last - k < k - before)) best = last;
        feature[base + k] = best < 0 ? -1 : int32_t(base + best);
      }
    }
  });

  // Passes along y, then x: lower envelope of parabolas, carrying the seed index. A voxel's
  // squared distance to its seed across the line is not stored: it follows from the seed's
  // index (half the memory a grid of distances would take and pass over). The lines of a pass
  // run across z, the contiguous axis, so they go in blocks of kBlock neighbours along z: each
  // cache line gathered or scattered is then used whole, not for one value.
  constexpr int kBlock = 16;
  const int z_blocks = (nz + kBlock - 1) / kBlock;
  // n samples per line, `stride` apart; line block b of `blocks` starts at first(b / z_blocks) +
  // its z; across(seed, b / z_blocks, k): the squared distance across the line to the seed.
  auto pass = [&](int n, int blocks, size_t stride, auto&& first, auto&& across) {
    tbb::parallel_for(tbb::blocked_range<int>(0, blocks), [&](const tbb::blocked_range<int>& r) {
      std::vector<LineScratch<Dist>> s(kBlock, LineScratch<Dist>(n));
      for (int b = r.begin(); b != r.end(); ++b) {
        const int k0 = (b % z_blocks) * kBlock, width = std::min(kBlock, nz - k0), outer = b / z_blocks;
        const size_t base = first(outer) + size_t(k0);
        for (int q = 0; q < n; ++q)
          for (int w = 0; w < width; ++w) {
            const int32_t f = feature[base + q * stride + w];
            s[w].feat[q] = f;
            s[w].f[q] = f < 0 ? kNone<Dist> : across(f, outer, k0 + w);
          }
        for (int w = 0; w < width; ++w) transform_line(n, s[w]);
        for (int q = 0; q < n; ++q)
          for (int w = 0; w < width; ++w) feature[base + q * stride + w] = s[w].arg[q] < 0 ? -1 : s[w].feat[s[w].arg[q]];
      }
    });
  };
  auto square = [](int d) { return Dist(d) * Dist(d); };
  const size_t plane = size_t(ny) * size_t(nz);
  // Along y: a seed on the voxel's z line, across it by z alone.
  pass(ny, nx * z_blocks, size_t(nz), [&](int i) { return size_t(i) * plane; },
       [&](int32_t f, int, int k) { return square(k - int(uint32_t(f) % uint32_t(nz))); });
  // Along x (lines at y = j): a seed in the voxel's x plane, across it by y and z.
  pass(nx, ny * z_blocks, plane, [&](int j) { return size_t(j) * size_t(nz); }, [&](int32_t f, int j, int k) {
    const Eigen::Vector3i c = shape.coords(size_t(f));
    return square(j - c.y()) + square(k - c.z());
  });
  return feature;
}

}  // namespace

GridVector<int32_t> nearest_seed_transform(const GridShape& shape, const uint8_t* seed, uint8_t bits) {
  const int64_t longest = shape.dims.maxCoeff();
  return 3 * longest * longest < int64_t(kNone<int32_t>) ? transform<int32_t>(shape, seed, bits)
                                                          : transform<int64_t>(shape, seed, bits);
}

}  // namespace spx
