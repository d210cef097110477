// The small vector types every stage computes with: plain structs with the usual operators,
// each written out component by component in one fixed order, so code that moves onto them
// keeps its exact results. Header-only and dependency-free (usable by the runtime side).
// Stored data keeps its own types (scene::Vec3 is the glTF float triple).
#pragma once

#include <cmath>

namespace vt {

template <class T>
struct Vec2T {
  T x = 0, y = 0;
};

template <class T>
struct Vec3T {
  T x = 0, y = 0, z = 0;
};

using Vec2d = Vec2T<double>;
using Vec3d = Vec3T<double>;
using Vec3f = Vec3T<float>;

template <class T>
Vec2T<T> operator+(Vec2T<T> a, Vec2T<T> b) {
  return {a.x + b.x, a.y + b.y};
}
template <class T>
Vec2T<T> operator-(Vec2T<T> a, Vec2T<T> b) {
  return {a.x - b.x, a.y - b.y};
}
template <class T>
Vec2T<T> operator*(Vec2T<T> a, T s) {
  return {a.x * s, a.y * s};
}
template <class T>
T dot(Vec2T<T> a, Vec2T<T> b) {
  return a.x * b.x + a.y * b.y;
}
// The z of the 3D cross product: twice the signed area of the triangle (0, a, b).
template <class T>
T cross(Vec2T<T> a, Vec2T<T> b) {
  return a.x * b.y - a.y * b.x;
}

template <class T>
Vec3T<T> operator+(Vec3T<T> a, Vec3T<T> b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
template <class T>
Vec3T<T> operator-(Vec3T<T> a, Vec3T<T> b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
template <class T>
Vec3T<T> operator*(Vec3T<T> a, T s) {
  return {a.x * s, a.y * s, a.z * s};
}
template <class T>
Vec3T<T> operator/(Vec3T<T> a, T s) {
  return {a.x / s, a.y / s, a.z / s};
}
template <class T>
T dot(Vec3T<T> a, Vec3T<T> b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
template <class T>
Vec3T<T> cross(Vec3T<T> a, Vec3T<T> b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
template <class T>
T length(Vec3T<T> a) {
  return std::sqrt(dot(a, a));
}
// a scaled to unit length (by the reciprocal of its length), or `fallback` when the length is
// not above 1e-30 or not finite.
template <class T>
Vec3T<T> normalized(Vec3T<T> a, Vec3T<T> fallback) {
  T l = length(a);
  if (!(l > T(1e-30)) || !std::isfinite(l)) return fallback;
  return a * (T(1) / l);
}

}  // namespace vt
