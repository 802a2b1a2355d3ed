#include "io/dense_field.hpp"

#include <sys/mman.h>

#include <cstdlib>

namespace spx::detail {
namespace {
constexpr size_t kHugePage = size_t(2) << 20;
// Below this a block is not worth a huge page of its own.
constexpr size_t kHugeFrom = size_t(8) << 20;
}  // namespace

void* allocate_grid_block(size_t bytes) {
  if (bytes < kHugeFrom) return ::operator new(bytes);
  const size_t rounded = (bytes + kHugePage - 1) / kHugePage * kHugePage;
  void* p = std::aligned_alloc(kHugePage, rounded);
  if (!p) throw std::bad_alloc();
#ifdef MADV_HUGEPAGE
  madvise(p, rounded, MADV_HUGEPAGE);  // a hint: where refused, ordinary pages
#endif
  return p;
}

void free_grid_block(void* p, size_t bytes) noexcept {
  if (bytes < kHugeFrom)
    ::operator delete(p);
  else
    std::free(p);
}

}  // namespace spx::detail
