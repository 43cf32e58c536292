#include "common/geometry/enclosing_sphere.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "common/geometry/test_meshes.h"

namespace meshseek {
namespace {

// Brute force: smallest sphere through 2, 3 or 4 of the points that contains
// all of them (the minimum enclosing sphere is always such a sphere).
double BruteForceRadius(const std::vector<Vec3f>& pts) {
  double best = 1e300;
  const std::size_t n = pts.size();
  auto check = [&](const Vec3d& c, double r) {
    if (r >= best) return;
    for (const Vec3f& p : pts) {
      if (Distance(Vec3d(p), c) > r * (1 + 1e-9)) return;
    }
    best = r;
  };
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i + 1; j < n; ++j) {
      const Vec3d a(pts[i]), b(pts[j]);
      check((a + b) * 0.5, 0.5 * Distance(a, b));
      for (std::size_t k = j + 1; k < n; ++k) {
        const Vec3d c(pts[k]);
        const Vec3d ab = b - a, ac = c - a, nn = Cross(ab, ac);
        if (SquaredNorm(nn) > 1e-20) {
          const Vec3d o = (Cross(nn, ab) * SquaredNorm(ac) + Cross(ac, nn) * SquaredNorm(ab)) /
                          (2 * SquaredNorm(nn));
          check(a + o, Norm(o));
        }
        for (std::size_t l = k + 1; l < n; ++l) {
          const Vec3d w = Vec3d(pts[l]) - a;
          const double det = 2 * Dot(ab, Cross(ac, w));
          if (std::abs(det) < 1e-12) continue;
          const Vec3d o = (Cross(ac, w) * SquaredNorm(ab) + Cross(w, ab) * SquaredNorm(ac) +
                           Cross(ab, ac) * SquaredNorm(w)) /
                          det;
          check(a + o, Norm(o));
        }
      }
    }
  }
  return best;
}

TEST(MinimumEnclosingSphereTest, MatchesBruteForceOnRandomSets) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 30; ++trial) {
    std::vector<Vec3f> pts;
    const int n = 3 + trial % 12;
    for (int i = 0; i < n; ++i) {
      pts.emplace_back(static_cast<float>(rng() % 2001) / 1000.0f - 1.0f,
                       static_cast<float>(rng() % 2001) / 1000.0f - 1.0f,
                       static_cast<float>(rng() % 2001) / 2000.0f);
    }
    auto s = MinimumEnclosingSphere(pts);
    ASSERT_TRUE(s.ok());
    EXPECT_NEAR(s->radius, BruteForceRadius(pts), 1e-6) << "trial " << trial;
    for (const Vec3f& p : pts) EXPECT_LE(Distance(Vec3d(p), s->center), s->radius * (1 + 1e-7));
  }
}

TEST(MinimumEnclosingSphereTest, KnownShapes) {
  auto cube = MinimumEnclosingSphere(testing_meshes::Cube(1.0f));
  ASSERT_TRUE(cube.ok());
  EXPECT_NEAR(cube->radius, std::sqrt(3.0), 1e-6);
  EXPECT_NEAR(Norm(cube->center), 0.0, 1e-6);

  TriangleMesh sphere = testing_meshes::Icosphere(3, 2.0f);
  for (Vec3f& v : sphere.vertices) v += Vec3f(5, -3, 1);
  auto s = MinimumEnclosingSphere(sphere);
  ASSERT_TRUE(s.ok());
  EXPECT_NEAR(s->radius, 2.0, 1e-5);
  EXPECT_NEAR(Distance(s->center, Vec3d(5, -3, 1)), 0.0, 1e-5);

  // Collinear and repeated points are degenerate supports.
  auto line = MinimumEnclosingSphere({{0, 0, 0}, {1, 0, 0}, {3, 0, 0}, {3, 0, 0}, {2, 0, 0}});
  ASSERT_TRUE(line.ok());
  EXPECT_NEAR(line->radius, 1.5, 1e-9);
}

TEST(MinimumEnclosingSphereTest, IgnoresUnreferencedVerticesAndRejectsBadInput) {
  TriangleMesh cube = testing_meshes::Cube(1.0f);
  cube.vertices.emplace_back(100.0f, 0.0f, 0.0f);  // not used by any triangle
  auto s = MinimumEnclosingSphere(cube);
  ASSERT_TRUE(s.ok());
  EXPECT_NEAR(s->radius, std::sqrt(3.0), 1e-6);
  EXPECT_FALSE(MinimumEnclosingSphere(std::vector<Vec3f>{}).ok());
  EXPECT_FALSE(MinimumEnclosingSphere(std::vector<Vec3f>{{NAN, 0, 0}}).ok());
}

}  // namespace
}  // namespace meshseek
