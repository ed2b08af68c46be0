// parallel_for: the one way the core splits independent work across threads (private header).
#pragma once

#include <algorithm>
#include <cstddef>
#include <exception>
#include <thread>
#include <vector>

#include "hedge/threads.h"

namespace hedge {

namespace testing {
//! For tests only: the smallest range of elements a parallel part gives a thread (0, the
//! default: each part's own tuned value), so that small meshes take the multi-threaded
//! paths.
void set_parallel_grain(std::size_t elements);
std::size_t parallel_grain();
//! How many times a parallel part has split its work across two or more threads, so that
//! tests can tell the multi-threaded paths really ran.
std::size_t parallel_splits();
void count_parallel_split();
}  // namespace testing

//! Runs fn(begin, end) over [0, n) split across up to `threads` threads (0: thread_count());
//! ranges below `grain` elements per thread stay on the calling thread, where a thread would
//! cost more than it saves. The first exception thrown by any part is rethrown after all parts
//! have finished.
template <class Fn>
void parallel_for(std::size_t n, unsigned threads, Fn&& fn, std::size_t grain = 32768) {
  threads = resolve_thread_count(threads);
  if (const std::size_t forced = testing::parallel_grain()) grain = forced;
  std::size_t t = std::min<std::size_t>(threads, std::max<std::size_t>(1, n / grain));
  if (t <= 1) {
    fn(std::size_t(0), n);
    return;
  }
  testing::count_parallel_split();
  std::vector<std::thread> pool;
  std::vector<std::exception_ptr> errors(t);
  for (std::size_t k = 1; k < t; ++k)
    pool.emplace_back([&, k] {
      try {
        fn(n * k / t, n * (k + 1) / t);
      } catch (...) {
        errors[k] = std::current_exception();
      }
    });
  try {
    fn(std::size_t(0), n / t);
  } catch (...) {
    errors[0] = std::current_exception();
  }
  for (auto& th : pool) th.join();
  for (auto& e : errors)
    if (e) std::rethrow_exception(e);
}

}  // namespace hedge
