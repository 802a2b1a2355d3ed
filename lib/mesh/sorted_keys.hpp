#pragma once
// Items grouped by a key without a hash table: (key, index) pairs sorted on both cores, so that
// equal keys lie together, each group in the order the items came, whatever the threads. On a
// scan of a million triangles a node per item (std::unordered_map) cost more than the sort.
#include <tbb/parallel_sort.h>

#include <cstdint>
#include <utility>
#include <vector>

namespace spx {

template <class Key>
using KeyedIndex = std::pair<Key, uint32_t>;

// The items' keys (key_of(i) for i < n) with their indices, sorted by key, then index.
template <class Key, class KeyOf>
std::vector<KeyedIndex<Key>> sorted_keys(size_t n, const KeyOf& key_of) {
  std::vector<KeyedIndex<Key>> out(n);
  for (size_t i = 0; i < n; ++i) out[i] = {key_of(i), uint32_t(i)};
  tbb::parallel_sort(out.begin(), out.end());
  return out;
}

}  // namespace spx
