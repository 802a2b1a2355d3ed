#pragma once
// Library errors raised deep inside a stage often do not know which file they concern;
// the stage's entry point names it.
#include "core/error.hpp"

namespace spx {

template <typename Fn>
auto about_file(const std::string& file, Fn&& fn) -> decltype(fn()) {
  try {
    return fn();
  } catch (const Error& e) {
    if (!e.subject().empty()) throw;
    throw Error(e.code(), file, e.what());
  }
}

}  // namespace spx
