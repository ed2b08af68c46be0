// Measures of one triangle, shared by the operations that judge triangles (decimate,
// remesh) and the report.
#pragma once

#include <algorithm>
#include <numbers>

#include "hedge/vec.h"

namespace hedge {

//! 2 r_in / r_out: 1 for an equilateral triangle, 0 for a degenerate one.
inline double triangle_quality(const Vec3d& a, const Vec3d& b, const Vec3d& c) {
  // 8 (s - la)(s - lb)(s - lc) / (la lb lc), with s the half perimeter (Heron).
  const double la = distance(b, c), lb = distance(a, c), lc = distance(a, b);
  const double s = 0.5 * (la + lb + lc);
  const double denom = la * lb * lc;
  if (denom <= 0) return 0;
  return std::clamp(8.0 * (s - la) * (s - lb) * (s - lc) / denom, 0.0, 1.0);
}

//! The smallest angle of the triangle, in degrees.
inline double triangle_min_angle(const Vec3d& a, const Vec3d& b, const Vec3d& c) {
  const double m = std::min({angle_at(a, b, c), angle_at(b, c, a), angle_at(c, a, b)});
  return m * 180.0 / std::numbers::pi;
}

}  // namespace hedge
