#include "common/geometry/enclosing_sphere.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include "absl/strings/str_cat.h"

namespace meshseek {
namespace {

constexpr double kRelTol = 1e-9;

bool Contains(const Sphere& s, const Vec3d& p) {
  const double r = s.radius * (1 + kRelTol) + 1e-300;
  return SquaredDistance(s.center, p) <= r * r;
}

Sphere FromTwo(const Vec3d& a, const Vec3d& b) { return {(a + b) * 0.5, 0.5 * Distance(a, b)}; }

Sphere SmallestContaining(std::initializer_list<Sphere> candidates,
                          std::initializer_list<Vec3d> points) {
  Sphere best{{}, std::numeric_limits<double>::infinity()};
  for (const Sphere& s : candidates) {
    if (s.radius >= best.radius) continue;
    bool ok = true;
    for (const Vec3d& p : points) ok = ok && Contains(s, p);
    if (ok) best = s;
  }
  return best;
}

// Circumscribed sphere of a triangle (centre in the triangle's plane), or the
// best two-point sphere if the triangle is degenerate or obtuse.
Sphere FromThree(const Vec3d& a, const Vec3d& b, const Vec3d& c) {
  const Sphere pair = SmallestContaining({FromTwo(a, b), FromTwo(a, c), FromTwo(b, c)}, {a, b, c});
  const Vec3d ab = b - a, ac = c - a;
  const Vec3d n = Cross(ab, ac);
  const double denom = 2 * SquaredNorm(n);
  if (denom <= 1e-30 * SquaredNorm(ab) * SquaredNorm(ac)) return pair;
  const Vec3d offset = (Cross(n, ab) * SquaredNorm(ac) + Cross(ac, n) * SquaredNorm(ab)) / denom;
  const Sphere circ{a + offset, Norm(offset)};
  return circ.radius < pair.radius ? circ : pair;
}

// Sphere through four points, or the best sphere of a subset if they are
// (nearly) coplanar.
Sphere FromFour(const Vec3d& a, const Vec3d& b, const Vec3d& c, const Vec3d& d) {
  const Sphere sub = SmallestContaining(
      {FromThree(a, b, c), FromThree(a, b, d), FromThree(a, c, d), FromThree(b, c, d)},
      {a, b, c, d});
  const Vec3d u = b - a, v = c - a, w = d - a;
  const double det = 2 * Dot(u, Cross(v, w));
  const double scale = Norm(u) * Norm(v) * Norm(w);
  if (std::abs(det) <= 1e-12 * scale) return sub;
  const Vec3d offset =
      (Cross(v, w) * SquaredNorm(u) + Cross(w, u) * SquaredNorm(v) + Cross(u, v) * SquaredNorm(w)) /
      det;
  const Sphere circ{a + offset, Norm(offset)};
  return circ.radius < sub.radius ? circ : sub;
}

// Welzl's recursion unrolled into its four levels: sphere of pts[0..n) with
// the given points on the boundary.
Sphere WithThree(const std::vector<Vec3d>& pts,
                 std::size_t n,
                 const Vec3d& q1,
                 const Vec3d& q2,
                 const Vec3d& q3) {
  Sphere s = FromThree(q1, q2, q3);
  for (std::size_t i = 0; i < n; ++i) {
    if (!Contains(s, pts[i])) s = FromFour(q1, q2, q3, pts[i]);
  }
  return s;
}

Sphere WithTwo(const std::vector<Vec3d>& pts, std::size_t n, const Vec3d& q1, const Vec3d& q2) {
  Sphere s = FromTwo(q1, q2);
  for (std::size_t i = 0; i < n; ++i) {
    if (!Contains(s, pts[i])) s = WithThree(pts, i, q1, q2, pts[i]);
  }
  return s;
}

Sphere WithOne(const std::vector<Vec3d>& pts, std::size_t n, const Vec3d& q) {
  Sphere s{q, 0};
  for (std::size_t i = 0; i < n; ++i) {
    if (!Contains(s, pts[i])) s = WithTwo(pts, i, q, pts[i]);
  }
  return s;
}

}  // namespace

absl::StatusOr<Sphere> MinimumEnclosingSphere(const std::vector<Vec3f>& points) {
  if (points.empty()) return absl::InvalidArgumentError("no points to enclose");
  std::vector<Vec3d> pts;
  pts.reserve(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!IsFinite(points[i])) {
      return absl::InvalidArgumentError(absl::StrCat("point ", i, " is not finite"));
    }
    pts.emplace_back(points[i]);
  }
  // Deterministic shuffle (splitmix64-driven Fisher-Yates) for expected linear time.
  uint64_t state = 0x9E3779B97F4A7C15ull;
  for (std::size_t i = pts.size(); i > 1; --i) {
    state += 0x9E3779B97F4A7C15ull;
    uint64_t z = state;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    z ^= z >> 31;
    std::swap(pts[i - 1], pts[z % i]);
  }
  Sphere s{pts[0], 0};
  for (std::size_t i = 1; i < pts.size(); ++i) {
    if (!Contains(s, pts[i])) s = WithOne(pts, i, pts[i]);
  }
  // Safety net against round-off in the degenerate fallbacks: never return a
  // sphere that misses a point.
  double max_sq = 0;
  for (const Vec3d& p : pts) max_sq = std::max(max_sq, SquaredDistance(s.center, p));
  s.radius = std::max(s.radius, std::sqrt(max_sq));
  return s;
}

absl::StatusOr<Sphere> MinimumEnclosingSphere(const TriangleMesh& mesh) {
  std::vector<bool> used(mesh.vertices.size(), false);
  for (const Triangle& t : mesh.triangles) {
    for (uint32_t v : t) {
      if (v < used.size()) used[v] = true;
    }
  }
  std::vector<Vec3f> points;
  points.reserve(mesh.vertices.size());
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v) {
    if (used[v]) points.push_back(mesh.vertices[v]);
  }
  return MinimumEnclosingSphere(points);
}

}  // namespace meshseek
