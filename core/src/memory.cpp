// The memory of the mesh's and the operations' big arrays (detail/memory.h).
#include "hedge/detail/memory.h"

#include <algorithm>
#include <cstdint>
#include <cstdlib>

#ifdef __linux__
#include <sys/mman.h>
#endif

namespace hedge::detail {

namespace {
constexpr std::size_t kHugePage = std::size_t(2) << 20;
}

void* allocate_array(std::size_t bytes, std::size_t alignment) {
  alignment = std::max(alignment, alignof(std::max_align_t));
  const std::size_t unit = bytes >= kHugePage ? kHugePage : alignment;
  // aligned_alloc wants a multiple of the alignment; at least one unit, so that an empty
  // array still gets a pointer of its own.
  const std::size_t rounded = std::max(unit, (bytes + unit - 1) / unit * unit);
  if (rounded < bytes) throw std::bad_alloc();
  void* p = std::aligned_alloc(unit, rounded);
  if (!p) throw std::bad_alloc();
#ifdef __linux__
  if (unit == kHugePage) madvise(p, rounded, MADV_HUGEPAGE);  // only a hint
#endif
  return p;
}

void free_array(void* p) noexcept { std::free(p); }

void advise_huge_pages(const void* p, std::size_t bytes) noexcept {
#ifdef __linux__
  const auto begin = reinterpret_cast<std::uintptr_t>(p);
  const std::uintptr_t first = (begin + kHugePage - 1) / kHugePage * kHugePage;
  const std::uintptr_t last = (begin + bytes) / kHugePage * kHugePage;
  if (last > first) madvise(reinterpret_cast<void*>(first), last - first, MADV_HUGEPAGE);  // only a hint
#else
  (void)p, (void)bytes;
#endif
}

}  // namespace hedge::detail
