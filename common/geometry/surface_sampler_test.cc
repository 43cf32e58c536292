#include "common/geometry/surface_sampler.h"

#include <gtest/gtest.h>

#include <cmath>

#include "common/geometry/test_meshes.h"

namespace meshseek {
namespace {

using testing_meshes::Cube;
using testing_meshes::Icosphere;
using testing_meshes::Plane;

TEST(SampleSurfaceTest, GivesExactCount) {
  const TriangleMesh sphere = Icosphere(3);
  for (int64_t n : {1, 2, 3, 7, 100, 1000, 1024, 4097, 15000}) {
    auto pts = SampleSurface(sphere, n);
    ASSERT_TRUE(pts.ok()) << pts.status();
    EXPECT_EQ(static_cast<int64_t>(pts->size()), n);
    EXPECT_EQ(pts->normals.size(), pts->size());
    EXPECT_EQ(pts->faces.size(), pts->size());
  }
}

TEST(SampleSurfaceTest, DensityIsUniformPerArea) {
  // Two squares side by side, one tessellated 16x finer than the other: each
  // half must get half of the points (error diffusion keeps the count per
  // region within one point of exact).
  TriangleMesh mesh = Plane(1);
  TriangleMesh fine = Plane(4, 1.0f, 0.0f);
  for (Vec3f& v : fine.vertices) v.x += 2.0f;  // [1, 3] x [-1, 1]
  testing_meshes::Append(fine, &mesh);
  const int n = 10000;
  auto pts = SampleSurface(mesh, n);
  ASSERT_TRUE(pts.ok());
  int right = 0;
  for (const Vec3f& p : pts->positions) right += p.x > 1.0f;
  EXPECT_NEAR(right, n / 2, 1);

  // Inside each triangle, points follow area too: count per quadrant of the
  // coarse square.
  int quadrant[4] = {0, 0, 0, 0};
  for (const Vec3f& p : pts->positions) {
    if (p.x <= 1.0f) quadrant[(p.x > 0) + 2 * (p.y > 0)]++;
  }
  for (int q : quadrant) EXPECT_NEAR(q, n / 8, n / 8 * 0.05);
}

TEST(SampleSurfaceTest, PointsLieOnTheirFaceWithItsNormal) {
  const TriangleMesh cube = Cube(1.0f);
  auto pts = SampleSurface(cube, 600);
  ASSERT_TRUE(pts.ok());
  for (std::size_t i = 0; i < pts->size(); ++i) {
    const uint32_t f = pts->faces[i];
    const Vec3d n = TriangleNormal(cube, f);
    const auto c = cube.Corners(f);
    EXPECT_NEAR(Dot(Vec3d(pts->positions[i]) - c[0], n), 0.0, 1e-6);
    EXPECT_NEAR(Norm(Vec3d(pts->normals[i]) - n), 0.0, 1e-6);
    // Inside the triangle: barycentric coordinates non-negative.
    const Vec3d p(pts->positions[i]);
    const double area = Norm(Cross(c[1] - c[0], c[2] - c[0]));
    const double a0 = Dot(Cross(c[1] - p, c[2] - p), n), a1 = Dot(Cross(c[2] - p, c[0] - p), n),
                 a2 = Dot(Cross(c[0] - p, c[1] - p), n);
    EXPECT_GE(a0, -1e-6 * area);
    EXPECT_GE(a1, -1e-6 * area);
    EXPECT_GE(a2, -1e-6 * area);
  }
  // Each of the 6 faces (2 triangles each) gets 100 points.
  std::vector<int> per_face(12, 0);
  for (uint32_t f : pts->faces) per_face[f]++;
  for (int side = 0; side < 6; ++side) EXPECT_EQ(per_face[2 * side] + per_face[2 * side + 1], 100);
}

TEST(SampleSurfaceTest, SkipsZeroAreaTrianglesAndIsDeterministic) {
  TriangleMesh mesh = Cube();
  mesh.triangles.push_back({0, 0, 1});  // degenerate
  mesh.triangles.push_back({0, 1, 1});
  auto a = SampleSurface(mesh, 333);
  auto b = SampleSurface(mesh, 333);
  ASSERT_TRUE(a.ok() && b.ok());
  for (uint32_t f : a->faces) EXPECT_LT(f, 12u);
  EXPECT_EQ(a->positions, b->positions);
}

TEST(SampleSurfaceTest, RejectsBadInput) {
  EXPECT_FALSE(SampleSurface(Cube(), 0).ok());
  TriangleMesh flat;
  flat.vertices = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
  flat.triangles = {{0, 1, 2}};
  const auto st = SampleSurface(flat, 10).status();
  EXPECT_EQ(st.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(st.message().find("area"), std::string::npos) << st;
}

}  // namespace
}  // namespace meshseek
