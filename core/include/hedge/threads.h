// How many threads the core may use: one setting for every parallel part (build, subdivide,
// smooth, remesh, distance). Results never depend on it: work is split at fixed points and
// partial results are combined in a fixed order.
#pragma once

#include <cstddef>

namespace hedge {

//! Sets the number of threads the core's parallel parts may use; 0 (the default) means
//! std::thread::hardware_concurrency(). Takes effect for operations started afterwards.
void set_thread_count(unsigned n);

//! The number of threads the core uses: the value set, or the hardware's (at least 1).
unsigned thread_count();

//! The number of threads asked for by `requested` (an options struct's `threads` field):
//! `requested` itself, or thread_count() when it is 0.
unsigned resolve_thread_count(unsigned requested);

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

}  // namespace hedge
