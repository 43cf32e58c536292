#include "common/geometry/triangle_bvh.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "common/geometry/test_meshes.h"

namespace meshseek {
namespace {

TEST(TriangleBvhTest, QueryMatchesBruteForce) {
  TriangleMesh mesh = testing_meshes::Icosphere(4);
  testing_meshes::Append(testing_meshes::Plane(3, 3.0f, 0.2f), &mesh);  // big + small triangles
  const TriangleBvh bvh(mesh);
  std::mt19937 rng(3);
  std::size_t total_got = 0, total_want = 0;
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
    // Every overlapping triangle, each once; extras come only from leaves
    // (at most kLeafSize - 1 per overlapping leaf, so few).
    ASSERT_TRUE(std::adjacent_find(got.begin(), got.end()) == got.end());
    ASSERT_TRUE(std::includes(got.begin(), got.end(), want.begin(), want.end())) << "query " << q;
    total_got += got.size();
    total_want += want.size();
  }
  EXPECT_LT(total_got, 2 * total_want);
}

// The query must return every triangle that truly intersects the box
// (checked with points sampled on the triangles), each once. Boxes from a
// tenth of the sphere to larger than it, so that whole subtrees fall inside.
TEST(TriangleBvhTest, OrientedQueryIsConservativeAndTight) {
  const TriangleMesh mesh = testing_meshes::Icosphere(4);
  const TriangleBvh bvh(mesh);
  std::mt19937 rng(9);
  auto r = [&] { return static_cast<double>(rng() % 2001) / 1000.0 - 1.0; };
  for (int q = 0; q < 100; ++q) {
    const Vec3d a0 = Normalized(Vec3d(r(), r(), r()));
    const Vec3d a1 = Normalized(Cross(a0, Vec3d(r(), r(), r())));
    const double scale = q < 50 ? 1.0 : 2.0 + 4.0 * std::abs(r());
    const Vec3d half(0.3 * scale, 0.2 * scale, 0.1 * scale);
    const OrientedBox box{Vec3d(r(), r(), r()), {a0, a1, Cross(a0, a1)}, {half.x, half.y, half.z}};
    std::vector<uint32_t> got;
    bvh.Query(box, &got);
    std::sort(got.begin(), got.end());
    ASSERT_TRUE(std::adjacent_find(got.begin(), got.end()) == got.end()) << "query " << q;
    for (uint32_t t = 0; t < mesh.triangles.size(); ++t) {
      const auto c = mesh.Corners(t);
      bool inside = false;
      for (double u = 0; u <= 1 && !inside; u += 0.125) {
        for (double v = 0; u + v <= 1 && !inside; v += 0.125) {
          const Vec3d p = c[0] + (c[1] - c[0]) * u + (c[2] - c[0]) * v - box.center;
          inside = std::abs(Dot(p, box.axes[0])) <= half.x &&
                   std::abs(Dot(p, box.axes[1])) <= half.y && std::abs(Dot(p, box.axes[2])) <= half.z;
        }
      }
      const bool returned = std::binary_search(got.begin(), got.end(), t);
      if (inside) {
        EXPECT_TRUE(returned) << "query " << q << " missed triangle " << t;
      }
    }
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

// A box holding the whole mesh: the root is inside, every triangle comes
// once, in the tree's order either way the box is given.
TEST(TriangleBvhTest, BoxesHoldingTheMeshReturnEveryTriangleOnce) {
  const TriangleMesh mesh = testing_meshes::Icosphere(3);
  const TriangleBvh bvh(mesh);
  Aabb all;
  all.Extend(Vec3f(-2, -2, -2));
  all.Extend(Vec3f(2, 2, 2));
  const Vec3d a0 = Normalized(Vec3d(1, 2, 3));
  const Vec3d a1 = Normalized(Cross(a0, Vec3d(0, 0, 1)));
  const OrientedBox turned{Vec3d(0.1, 0, 0), {a0, a1, Cross(a0, a1)}, {1.5, 1.5, 1.5}};
  std::vector<uint32_t> axis_aligned, oriented;
  bvh.Query(all, &axis_aligned);
  bvh.Query(turned, &oriented);
  EXPECT_EQ(axis_aligned, oriented);
  std::sort(oriented.begin(), oriented.end());
  ASSERT_EQ(oriented.size(), mesh.triangles.size());
  for (uint32_t t = 0; t < oriented.size(); ++t) ASSERT_EQ(oriented[t], t);
}

}  // namespace
}  // namespace meshseek
