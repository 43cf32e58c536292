#include "common/geometry/point_grid.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

namespace meshseek {
namespace {

TEST(PointGridTest, RadiusQueryMatchesBruteForce) {
  std::mt19937 rng(11);
  auto r = [&] { return static_cast<float>(rng() % 10001) / 5000.0f - 1.0f; };
  std::vector<Vec3f> pts;
  for (int i = 0; i < 3000; ++i) pts.emplace_back(r(), r(), 0.1f * r());
  for (float cell : {0.05f, 0.2f, 1.5f}) {
    const PointGrid grid(pts, cell);
    for (int q = 0; q < 100; ++q) {
      const Vec3f c(1.3f * r(), 1.3f * r(), 0.3f * r());
      const float radius = 0.01f + 0.3f * (r() + 1.0f);
      std::vector<uint32_t> got;
      grid.RadiusQuery(c, radius, &got);
      std::sort(got.begin(), got.end());
      std::vector<uint32_t> want;
      for (uint32_t i = 0; i < pts.size(); ++i) {
        if (SquaredDistance(pts[i], c) <= radius * radius) want.push_back(i);
      }
      ASSERT_EQ(got, want) << "cell " << cell << " query " << q;
    }
  }
}

}  // namespace
}  // namespace meshseek
