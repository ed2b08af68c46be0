// Heap counting for hedge_bench: the malloc family is interposed for the whole process
// (operator new, OpenMesh's shared library and hedge's aligned scratch arrays all end up
// here), and the usable size of every block is counted while a HeapWindow is open.
// Counting malloc rather than operator new catches memory that bypasses new
// (aligned_alloc, posix_memalign), so peaks include every temporary array.
#include <errno.h>
#include <malloc.h>

#include <atomic>
#include <cstddef>
#include <cstdint>

#include "bench.h"

extern "C" {
void* __libc_malloc(std::size_t);
void __libc_free(void*);
void* __libc_calloc(std::size_t, std::size_t);
void* __libc_realloc(void*, std::size_t);
void* __libc_memalign(std::size_t, std::size_t);
void* __libc_valloc(std::size_t);
void* __libc_pvalloc(std::size_t);
}

namespace {
std::atomic<bool> g_counting{false};
std::atomic<std::int64_t> g_live{0};
std::atomic<std::int64_t> g_peak{0};

inline void count_alloc(void* p) {
  if (!p || !g_counting.load(std::memory_order_relaxed)) return;
  const auto bytes = static_cast<std::int64_t>(malloc_usable_size(p));
  const std::int64_t live = g_live.fetch_add(bytes, std::memory_order_relaxed) + bytes;
  std::int64_t peak = g_peak.load(std::memory_order_relaxed);
  while (live > peak && !g_peak.compare_exchange_weak(peak, live, std::memory_order_relaxed)) {
  }
}
inline void count_free(void* p) {
  if (!p || !g_counting.load(std::memory_order_relaxed)) return;
  g_live.fetch_sub(static_cast<std::int64_t>(malloc_usable_size(p)), std::memory_order_relaxed);
}
}  // namespace

extern "C" {
void* malloc(std::size_t n) {
  void* p = __libc_malloc(n);
  count_alloc(p);
  return p;
}
void free(void* p) {
  count_free(p);
  __libc_free(p);
}
void* calloc(std::size_t count, std::size_t size) {
  void* p = __libc_calloc(count, size);
  count_alloc(p);
  return p;
}
void* realloc(void* p, std::size_t n) {
  count_free(p);
  void* q = __libc_realloc(p, n);
  if (q) {
    count_alloc(q);
  } else if (p && n) {
    count_alloc(p);  // failed: p is still there
  }
  return q;
}
void* memalign(std::size_t align, std::size_t n) {
  void* p = __libc_memalign(align, n);
  count_alloc(p);
  return p;
}
void* aligned_alloc(std::size_t align, std::size_t n) { return memalign(align, n); }
int posix_memalign(void** out, std::size_t align, std::size_t n) {
  if (align < sizeof(void*) || (align & (align - 1)) != 0) return EINVAL;
  void* p = memalign(align, n);
  if (!p) return ENOMEM;
  *out = p;
  return 0;
}
void* valloc(std::size_t n) {
  void* p = __libc_valloc(n);
  count_alloc(p);
  return p;
}
void* pvalloc(std::size_t n) {
  void* p = __libc_pvalloc(n);
  count_alloc(p);
  return p;
}
}

namespace bench {

namespace {
std::int64_t malloc_in_use() {
  struct mallinfo2 info = mallinfo2();
  return static_cast<std::int64_t>(info.uordblks + info.hblkhd);
}
}  // namespace

HeapWindow::HeapWindow() : malloc_start_(malloc_in_use()) {
  g_live.store(0);
  g_peak.store(0);
  g_counting.store(true);
}
HeapWindow::~HeapWindow() { g_counting.store(false); }
std::int64_t HeapWindow::live() const { return g_live.load(); }
std::int64_t HeapWindow::peak() const { return g_peak.load(); }
std::int64_t HeapWindow::malloc_live() const { return malloc_in_use() - malloc_start_; }

}  // namespace bench
