// Small fixed-size vectors for geometry. Positions are stored as float (both hosts use
// float); computations that need it promote to double.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>

namespace hedge {

template <class T, int N>
struct Vec {
  std::array<T, N> data{};

  constexpr T& operator[](int i) { return data[i]; }
  constexpr const T& operator[](int i) const { return data[i]; }
  constexpr bool operator==(const Vec&) const = default;

  template <class U>
  constexpr explicit operator Vec<U, N>() const {
    Vec<U, N> r;
    for (int i = 0; i < N; ++i) r[i] = static_cast<U>(data[i]);
    return r;
  }
  constexpr Vec& operator+=(const Vec& o) {
    for (int i = 0; i < N; ++i) data[i] += o[i];
    return *this;
  }
  constexpr Vec& operator-=(const Vec& o) {
    for (int i = 0; i < N; ++i) data[i] -= o[i];
    return *this;
  }
  constexpr Vec& operator*=(T s) {
    for (int i = 0; i < N; ++i) data[i] *= s;
    return *this;
  }
  constexpr Vec& operator/=(T s) {
    for (int i = 0; i < N; ++i) data[i] /= s;
    return *this;
  }
  friend constexpr Vec operator+(Vec a, const Vec& b) { return a += b; }
  friend constexpr Vec operator-(Vec a, const Vec& b) { return a -= b; }
  friend constexpr Vec operator*(Vec a, T s) { return a *= s; }
  friend constexpr Vec operator*(T s, Vec a) { return a *= s; }
  friend constexpr Vec operator/(Vec a, T s) { return a /= s; }
  friend constexpr Vec operator-(Vec a) {
    for (int i = 0; i < N; ++i) a[i] = -a[i];
    return a;
  }
};

using Vec2f = Vec<float, 2>;
using Vec3f = Vec<float, 3>;
using Vec3d = Vec<double, 3>;
using Point = Vec3f;

template <class T, int N>
constexpr T dot(const Vec<T, N>& a, const Vec<T, N>& b) {
  T s = 0;
  for (int i = 0; i < N; ++i) s += a[i] * b[i];
  return s;
}
template <class T>
constexpr Vec<T, 3> cross(const Vec<T, 3>& a, const Vec<T, 3>& b) {
  return {{a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]}};
}
template <class T, int N>
inline T sqrnorm(const Vec<T, N>& a) {
  return dot(a, a);
}
template <class T, int N>
inline T norm(const Vec<T, N>& a) {
  return std::sqrt(dot(a, a));
}
template <class T, int N>
inline T distance(const Vec<T, N>& a, const Vec<T, N>& b) {
  return norm(a - b);
}
//! a / |a|, or a unchanged when it has zero length.
template <class T, int N>
inline Vec<T, N> normalize(Vec<T, N> a) {
  T n = norm(a);
  return n > T(0) ? a / n : a;
}
//! The angle between u and v in radians, 0 to pi (0 when either is zero); atan2 rather than
//! acos, which loses its precision near 0 and pi.
template <class T>
inline T angle_between(const Vec<T, 3>& u, const Vec<T, 3>& v) {
  return std::atan2(norm(cross(u, v)), dot(u, v));
}
//! The angle of triangle (corner, a, b) at corner, in radians.
template <class T>
inline T angle_at(const Vec<T, 3>& corner, const Vec<T, 3>& a, const Vec<T, 3>& b) {
  return angle_between(a - corner, b - corner);
}
inline Vec3d to_double(const Vec3f& p) { return static_cast<Vec3d>(p); }
inline Vec3f to_float(const Vec3d& p) { return static_cast<Vec3f>(p); }

}  // namespace hedge
