#pragma once
// SplitMix64: the one seeded generator for surface samples, the cover's search, blend weights
// and the crash host's jitter. The same numbers on every platform and standard library (std::
// distributions differ between them), from a single 64-bit state.
#include <cmath>
#include <cstdint>

namespace spx {

struct SplitMix {
  uint64_t state;
  uint64_t next() {
    uint64_t z = (state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  double uniform() { return double(next() >> 11) * 0x1.0p-53; }  // [0, 1)
  double exponential() { return -std::log1p(-uniform()); }       // rate 1
};

}  // namespace spx
