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

}  // namespace hedge
