// The core's one thread-count setting (hedge/threads.h).
#include "hedge/threads.h"

#include <atomic>
#include <thread>

#include "parallel.h"

namespace hedge {
namespace {
std::atomic<unsigned> g_thread_count{0};
std::atomic<std::size_t> g_parallel_grain{0};
std::atomic<std::size_t> g_parallel_splits{0};
}  // namespace

void set_thread_count(unsigned n) { g_thread_count.store(n, std::memory_order_relaxed); }

unsigned thread_count() {
  const unsigned n = g_thread_count.load(std::memory_order_relaxed);
  if (n) return n;
  const unsigned hardware = std::thread::hardware_concurrency();
  return hardware ? hardware : 1;
}

unsigned resolve_thread_count(unsigned requested) { return requested ? requested : thread_count(); }

namespace testing {
void set_parallel_grain(std::size_t elements) { g_parallel_grain.store(elements, std::memory_order_relaxed); }
std::size_t parallel_grain() { return g_parallel_grain.load(std::memory_order_relaxed); }
std::size_t parallel_splits() { return g_parallel_splits.load(std::memory_order_relaxed); }
void count_parallel_split() { g_parallel_splits.fetch_add(1, std::memory_order_relaxed); }
}  // namespace testing

}  // namespace hedge
