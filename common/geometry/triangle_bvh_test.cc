#include "common/geometry/triangle_bvh.h"

#include <algorithm>
#include <random>

#include <gtest/gtest.h>

#include "common/geometry/test_meshes.h"

namespace meshseek {
namespace {

TEST(TriangleBvhTest, QueryMatchesBruteForce) {
  TriangleMesh mesh = testing_meshes::Icosphere(4);
  testing_meshes::Append(testing_meshes::Plane(3, 3.0f, 0.2f), &mesh);  // big + small triangles
  const TriangleBvh bvh(mesh);
  std::mt19937 rng(3);
  for (int q = 0; q < 200; ++q) {
    auto r = [&] { return static_cast<float>(rng() % 4001) / 1000.0f - 2.0f; };
    const Vec3f c(r(), r(), r());
    const float h = static_cast<float>(rng() % 500) / 1000.0f;
    Aabb box;
    box.Extend(c - Vec3f(h, h, h));
    box.Extend(c + Vec3f(h, h, h));
    std::vector<uint32_t> got;
    bvh.Query(box, &got);
    std::sort(got.begin(), got.end());
    std::vector<uint32_t> want;
    for (uint32_t t = 0; t < mesh.triangles.size(); ++t) {
      Aabb tb;
      for (uint32_t v : mesh.triangles[t]) tb.Extend(mesh.vertices[v]);
      if (tb.Overlaps(box)) want.push_back(t);
    }
    ASSERT_EQ(got, want) << "query " << q;
  }
}

TEST(TriangleBvhTest, HandlesTinyMeshes) {
  const TriangleBvh empty{TriangleMesh()};
  std::vector<uint32_t> out;
  Aabb all;
  all.Extend(Vec3f(-1e6f, -1e6f, -1e6f));
  all.Extend(Vec3f(1e6f, 1e6f, 1e6f));
  empty.Query(all, &out);
  EXPECT_TRUE(out.empty());
  const TriangleBvh cube(testing_meshes::Cube());
  cube.Query(all, &out);
  EXPECT_EQ(out.size(), 12u);
}

}  // namespace
}  // namespace meshseek
