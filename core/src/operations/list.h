// The registration list: one line per operation, in menu order. Each X(name) refers to
// `Operation name_operation()`, defined next to its algorithm in src/operations/name.cpp.
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
