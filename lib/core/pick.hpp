#pragma once
// The entries of a vector at some indices, in the indices' order.
#include <cstddef>
#include <vector>

namespace spx {

template <class T, class Index>
std::vector<T> pick(const std::vector<T>& all, const std::vector<Index>& which) {
  std::vector<T> out;
  out.reserve(which.size());
  for (Index i : which) out.push_back(all[size_t(i)]);
  return out;
}

}  // namespace spx
