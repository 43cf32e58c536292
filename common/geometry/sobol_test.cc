#include "common/geometry/sobol.h"

#include <gtest/gtest.h>

namespace meshseek {
namespace {

TEST(Sobol2DTest, MatchesNumericalRecipesTestVectors) {
  // docs/design.md 2.1: the first ten points of NR's sobseq in two dimensions.
  const double expected[10][2] = {{0.5, 0.5},
                                  {0.25, 0.75},
                                  {0.75, 0.25},
                                  {0.375, 0.625},
                                  {0.875, 0.125},
                                  {0.125, 0.375},
                                  {0.625, 0.875},
                                  {0.3125, 0.3125},
                                  {0.8125, 0.8125},
                                  {0.0625, 0.5625}};
  Sobol2D sobol;
  for (const auto& e : expected) {
    const auto p = sobol.Next();
    EXPECT_DOUBLE_EQ(p[0], e[0]);
    EXPECT_DOUBLE_EQ(p[1], e[1]);
  }
}

TEST(Sobol2DTest, IsLowDiscrepancy) {
  // Each coordinate of points 0 .. 2^m - 1 (NR starts at point 1; point 0 is
  // the origin) visits every interval [k 2^-m, (k+1) 2^-m) exactly once, and
  // in 2-D the first 4096 points fill a 16 x 16 grid far more evenly than
  // random points would (binomial sd of a cell count: 4).
  constexpr int m = 12, n = 1 << m;
  Sobol2D sobol;
  std::vector<std::array<double, 2>> pts = {{0.0, 0.0}};
  for (int i = 1; i < n; ++i) pts.push_back(sobol.Next());
  for (int dim = 0; dim < 2; ++dim) {
    std::vector<int> hits(n, 0);
    for (const auto& p : pts) hits[static_cast<int>(p[dim] * n)]++;
    for (int h : hits) ASSERT_EQ(h, 1) << "dimension " << dim;
  }
  std::vector<int> grid(256, 0);
  for (const auto& p : pts) grid[static_cast<int>(p[0] * 16) * 16 + static_cast<int>(p[1] * 16)]++;
  for (int c : grid) EXPECT_NEAR(c, 16, 2);
}

TEST(Sobol2DTest, IsDeterministic) {
  Sobol2D a, b;
  for (int i = 0; i < 1000; ++i) EXPECT_EQ(a.Next(), b.Next());
}

}  // namespace
}  // namespace meshseek
