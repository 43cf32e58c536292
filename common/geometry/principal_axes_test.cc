#include "common/geometry/principal_axes.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace meshseek {
namespace {

TEST(PrincipalAxesTest, RecoversAxesOfAnAnisotropicCloud) {
  std::mt19937 rng(5);
  auto r = [&] { return static_cast<double>(rng() % 20001) / 10000.0 - 1.0; };
  const Vec3d e0 = Normalized(Vec3d(1, 2, 3));
  const Vec3d e1 = Normalized(Cross(e0, Vec3d(0, 0, 1)));
  const Vec3d e2 = Cross(e0, e1);
  std::vector<Vec3f> pts;
  for (int i = 0; i < 20000; ++i) {
    pts.emplace_back(Vec3d(4, 5, 6) + e0 * (5 * r()) + e1 * (2 * r()) + e2 * (0.2 * r()));
  }
  const PrincipalAxes pa = ComputePrincipalAxes(pts);
  EXPECT_NEAR(std::abs(Dot(pa.axes[0], e0)), 1.0, 1e-3);
  EXPECT_NEAR(std::abs(Dot(pa.axes[1], e1)), 1.0, 1e-3);
  EXPECT_NEAR(std::abs(Dot(pa.axes[2], e2)), 1.0, 1e-3);
  EXPECT_NEAR(Dot(Cross(pa.axes[0], pa.axes[1]), pa.axes[2]), 1.0, 1e-12);  // right-handed
  EXPECT_NEAR(Norm(pa.centroid - Vec3d(4, 5, 6)), 0.0, 0.05);
  EXPECT_GT(pa.variances[0], pa.variances[1]);
  EXPECT_GT(pa.variances[1], pa.variances[2]);
  EXPECT_NEAR(pa.variances[0], 25.0 / 3, 0.3);  // uniform on [-5, 5]
}

TEST(PrincipalAxesTest, UsesOnlyTheSubset) {
  std::vector<Vec3f> pts = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {0, 0, 100}};
  const std::vector<uint32_t> subset = {0, 1, 2};
  const PrincipalAxes pa = ComputePrincipalAxes(pts, &subset);
  EXPECT_NEAR(std::abs(pa.axes[0].x), 1.0, 1e-12);
  EXPECT_NEAR(pa.centroid.x, 1.0, 1e-12);
}

TEST(PrincipalAxesTest, WeightedAxesAreCentredOnTheGivenPointAndFavourNearPoints) {
  // A plane z = 0 with a far wall at x = 0.9: plain PCA of the ball of radius
  // 1 is pulled by the wall; distance weighting keeps the plane's normal.
  std::vector<Vec3f> pts;
  for (int i = -10; i <= 10; ++i) {
    for (int j = -10; j <= 10; ++j) pts.emplace_back(0.1f * i, 0.05f * j, 0.0f);
  }
  for (int j = -10; j <= 10; ++j) {
    for (int k = 0; k < 10; ++k) pts.emplace_back(0.9f, 0.05f * j, 0.05f * k);
  }
  std::vector<uint32_t> all(pts.size());
  for (uint32_t i = 0; i < all.size(); ++i) all[i] = i;
  const PrincipalAxes weighted = ComputeWeightedPrincipalAxes(pts, all, Vec3d(0, 0, 0), 1.0);
  EXPECT_EQ(weighted.centroid, Vec3d(0, 0, 0));
  EXPECT_NEAR(std::abs(weighted.axes[2].z), 1.0, 2e-3);
  EXPECT_NEAR(std::abs(weighted.axes[0].x), 1.0, 1e-3);  // the plane's long side
  const PrincipalAxes plain = ComputePrincipalAxes(pts, &all);
  EXPECT_LT(std::abs(plain.axes[2].z), std::abs(weighted.axes[2].z));
}

TEST(SymmetricEigen3Test, DiagonalisesAndHandlesRepeatedEigenvalues) {
  std::array<double, 3> values;
  std::array<Vec3d, 3> vectors;
  SymmetricEigen3({{{2, 1, 0}, {1, 2, 0}, {0, 0, 3}}}, &values, &vectors);
  EXPECT_NEAR(values[0], 3, 1e-12);
  EXPECT_NEAR(values[1], 3, 1e-12);
  EXPECT_NEAR(values[2], 1, 1e-12);
  EXPECT_NEAR(std::abs(Dot(vectors[2], Normalized(Vec3d(1, -1, 0)))), 1.0, 1e-12);
  SymmetricEigen3({{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}}, &values, &vectors);
  for (double v : values) EXPECT_DOUBLE_EQ(v, 1.0);
}

}  // namespace
}  // namespace meshseek
