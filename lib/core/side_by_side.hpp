#pragma once
// Steps that need nothing of one another, run at once on the task scheduler. Each keeps its own
// exception, and the first in the order given is rethrown once all have ended: a failure is
// reported as running them one after another would report it, and none is left running.
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include <cstddef>
#include <exception>
#include <tuple>
#include <utility>
#include <vector>

namespace spx {

namespace detail {
template <class Step>
void keep_exception(std::exception_ptr& failed, Step&& step) {
  try {
    step();
  } catch (...) {
    failed = std::current_exception();
  }
}

template <class Tuple, size_t... I>
void side_by_side_indexed(Tuple& steps, std::exception_ptr* failed, std::index_sequence<I...>) {
  tbb::parallel_invoke([&] { keep_exception(failed[I], std::get<I>(steps)); }...);
}
}  // namespace detail

template <class... Steps>
void side_by_side(Steps&&... steps) {
  static_assert(sizeof...(Steps) >= 2, "side_by_side runs two steps or more");
  std::exception_ptr failed[sizeof...(Steps)];
  auto all = std::forward_as_tuple(steps...);
  detail::side_by_side_indexed(all, failed, std::index_sequence_for<Steps...>{});
  for (const std::exception_ptr& e : failed)
    if (e) std::rethrow_exception(e);
}

// step(i) for i in [0, count), at once; the failure of the lowest i is rethrown.
template <class Step>
void each_side_by_side(size_t count, Step&& step) {
  std::vector<std::exception_ptr> failed(count);
  tbb::parallel_for(size_t(0), count, [&](size_t i) { detail::keep_exception(failed[i], [&] { step(i); }); });
  for (const std::exception_ptr& e : failed)
    if (e) std::rethrow_exception(e);
}

}  // namespace spx
