// A small 3-vector for geometry code. Storage uses float (meshes, point sets,
// wire format); arithmetic that accumulates (areas, moments, frames) uses
// double. Conversions between the two are explicit.
#ifndef MESHSEEK_COMMON_GEOMETRY_VEC3_H_
#define MESHSEEK_COMMON_GEOMETRY_VEC3_H_

#include <cmath>
#include <ostream>

namespace meshseek {

template <typename T>
struct Vec3T {
  T x = 0, y = 0, z = 0;

  constexpr Vec3T() = default;
  constexpr Vec3T(T x_, T y_, T z_) : x(x_), y(y_), z(z_) {}
  template <typename U>
  constexpr explicit Vec3T(const Vec3T<U>& o)
      : x(static_cast<T>(o.x)), y(static_cast<T>(o.y)), z(static_cast<T>(o.z)) {}

  constexpr T operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
  T& operator[](int i) { return i == 0 ? x : (i == 1 ? y : z); }

  constexpr Vec3T operator+(const Vec3T& o) const { return {x + o.x, y + o.y, z + o.z}; }
  constexpr Vec3T operator-(const Vec3T& o) const { return {x - o.x, y - o.y, z - o.z}; }
  constexpr Vec3T operator-() const { return {-x, -y, -z}; }
  constexpr Vec3T operator*(T s) const { return {x * s, y * s, z * s}; }
  constexpr Vec3T operator/(T s) const { return {x / s, y / s, z / s}; }
  Vec3T& operator+=(const Vec3T& o) {
    x += o.x;
    y += o.y;
    z += o.z;
    return *this;
  }
  Vec3T& operator-=(const Vec3T& o) {
    x -= o.x;
    y -= o.y;
    z -= o.z;
    return *this;
  }
  Vec3T& operator*=(T s) {
    x *= s;
    y *= s;
    z *= s;
    return *this;
  }
  constexpr bool operator==(const Vec3T& o) const { return x == o.x && y == o.y && z == o.z; }
  constexpr bool operator!=(const Vec3T& o) const { return !(*this == o); }
};

using Vec3f = Vec3T<float>;
using Vec3d = Vec3T<double>;

template <typename T>
constexpr Vec3T<T> operator*(T s, const Vec3T<T>& v) {
  return v * s;
}
template <typename T>
constexpr T Dot(const Vec3T<T>& a, const Vec3T<T>& b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
template <typename T>
constexpr Vec3T<T> Cross(const Vec3T<T>& a, const Vec3T<T>& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
template <typename T>
constexpr T SquaredNorm(const Vec3T<T>& v) {
  return Dot(v, v);
}
template <typename T>
T Norm(const Vec3T<T>& v) {
  return std::sqrt(Dot(v, v));
}
template <typename T>
T SquaredDistance(const Vec3T<T>& a, const Vec3T<T>& b) {
  return SquaredNorm(a - b);
}
template <typename T>
T Distance(const Vec3T<T>& a, const Vec3T<T>& b) {
  return Norm(a - b);
}
// Unit vector along v, or the zero vector if v has (near) zero length.
template <typename T>
Vec3T<T> Normalized(const Vec3T<T>& v) {
  const T n = Norm(v);
  return n > T(0) ? v / n : Vec3T<T>();
}
template <typename T>
bool IsFinite(const Vec3T<T>& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}
template <typename T>
std::ostream& operator<<(std::ostream& os, const Vec3T<T>& v) {
  return os << '(' << v.x << ", " << v.y << ", " << v.z << ')';
}

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_GEOMETRY_VEC3_H_
