#pragma once
// FNV-1a, 64 bit: the one hash for deterministic file ids, cache keys and state digests; and a
// double's bits, for keys that tell values apart exactly.
#include <cstddef>
#include <cstdint>
#include <cstring>

namespace spx {

constexpr uint64_t kFnvOffset = 14695981039346656037ull;
constexpr uint64_t kFnvPrime = 1099511628211ull;

inline uint64_t fnv1a(uint64_t h, const void* data, size_t size) {
  const unsigned char* p = static_cast<const unsigned char*>(data);
  for (size_t i = 0; i < size; ++i) h = (h ^ p[i]) * kFnvPrime;
  return h;
}

// The bytes of `v`'s values (plain ones: numbers, fixed-size Eigen vectors).
template <class Vector>
uint64_t fnv1a_values(uint64_t h, const Vector& v) {
  return fnv1a(h, v.data(), v.size() * sizeof(v[0]));
}

// The bits of `v` (-0 and +0 apart, each NaN as its own bits).
inline uint64_t bits_of(double v) {
  uint64_t out;
  std::memcpy(&out, &v, sizeof v);
  return out;
}

// A hash's bits spread (SplitMix64's finalizer): summed over a set, the sum names the set
// whatever its order.
inline uint64_t mix64(uint64_t x) {
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

}  // namespace spx
