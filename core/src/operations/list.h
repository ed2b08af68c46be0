// The registration list: one line per operation, in menu order. Each X(name) refers to
// `Operation name_operation()`, defined next to its algorithm in src/operations/name.cpp
// through a Binding (binding.h).
#pragma once

#define HEDGE_OPERATIONS(X) \
  X(report)             \
  X(decimate)           \
  X(subdivide)          \
  X(smooth)             \
  X(make_delaunay)      \
  X(triangulate)        \
  X(remesh)             \
  X(fill_holes)         \
  X(repair)

namespace hedge {
struct Operation;
#define HEDGE_DECLARE_OPERATION(name) Operation name##_operation();
HEDGE_OPERATIONS(HEDGE_DECLARE_OPERATION)
#undef HEDGE_DECLARE_OPERATION
}  // namespace hedge
