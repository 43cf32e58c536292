#include "common/features/depth_image.h"

#include <gtest/gtest.h>

#include <cmath>

#include "common/geometry/test_meshes.h"

namespace meshseek {
namespace {

using testing_meshes::Icosphere;
using testing_meshes::Plane;

// Centre of pixel (row, col) in the front camera's (x right, y up) plane.
void PixelCentre(int row, int col, int size, double s, double* x, double* y) {
  *x = -s + (col + 0.5) * 2 * s / size;
  *y = s - (row + 0.5) * 2 * s / size;
}

TEST(DepthImageTest, TiltedPlaneGivesAnalyticDepths) {
  // Plane z = 0.25 x, seen from above at the origin with s = 0.5.
  TriangleMesh plane = Plane(8, 2.0f);
  for (Vec3f& v : plane.vertices) v.z = 0.25f * v.x;
  const TriangleBvh bvh(plane);
  DepthImageOptions options;
  DepthImageRenderer renderer(plane, bvh, options);
  const double s = 0.5;
  DepthImage front, back;
  renderer.RenderPair({{0, 0, 0}, {0, 1, 0}, {0, 0, 1}, s}, &front, &back);
  ASSERT_EQ(front.size, 21);
  const Vec3d right = Cross(Vec3d(0, 1, 0), Vec3d(0, 0, 1));  // (1, 0, 0)
  for (int row = 0; row < front.size; ++row) {
    for (int col = 0; col < front.size; ++col) {
      double x, y;
      PixelCentre(row, col, front.size, s, &x, &y);
      const double h = 0.25 * x * right.x;
      EXPECT_NEAR(front.at(row, col), s - h, 1e-5) << row << "," << col;
      // The back camera looks up with its right vector mirrored: column c of the
      // back image sees the point at -x(c).
      EXPECT_NEAR(back.at(row, col), s + 0.25 * (-x), 1e-5) << row << "," << col;
    }
  }
}

TEST(DepthImageTest, SphereCapFromOutsideAndInside) {
  const TriangleMesh sphere = Icosphere(5, 1.0f);
  const TriangleBvh bvh(sphere);
  DepthImageRenderer renderer(sphere, bvh, DepthImageOptions());
  const double s = 0.5;
  DepthImage front, back;
  renderer.RenderPair({{0, 0, 1}, {0, 1, 0}, {0, 0, 1}, s}, &front, &back);
  for (int row = 0; row < front.size; ++row) {
    for (int col = 0; col < front.size; ++col) {
      double x, y;
      PixelCentre(row, col, front.size, s, &x, &y);
      const double h = std::sqrt(1 - x * x - y * y) - 1;  // cap height relative to the top
      EXPECT_NEAR(front.at(row, col), s - h, 2e-3) << row << "," << col;
      EXPECT_NEAR(back.at(row, col), s + h, 2e-3) << row << "," << col;  // inside of the cap
    }
  }
}

TEST(DepthImageTest, OnlyTheSupportCubeIsDrawn) {
  // Two parallel planes: one at h = 0.2 (inside the cube) and one at h = 0.8
  // (behind the front camera at h = 0.5): the front camera must see the first.
  TriangleMesh mesh = Plane(2, 1.0f, 0.2f);
  testing_meshes::Append(Plane(2, 1.0f, 0.8f), &mesh);
  const TriangleBvh bvh(mesh);
  DepthImageRenderer renderer(mesh, bvh, DepthImageOptions());
  DepthImage front, back;
  renderer.RenderPair({{0, 0, 0}, {0, 1, 0}, {0, 0, 1}, 0.5}, &front, &back);
  for (float d : front.depth) EXPECT_NEAR(d, 0.3, 1e-6);
  for (float d : back.depth) EXPECT_NEAR(d, 0.7, 1e-6);
}

TEST(DepthImageTest, InvariantUnderRigidMotionAndScale) {
  TriangleMesh mesh = Icosphere(4, 1.0f);
  for (Vec3f& v : mesh.vertices) v.z *= 0.6f + 0.3f * v.x;  // something without symmetry
  const Vec3d p(mesh.vertices[7]), up = Normalized(Vec3d(1, 2, 0)),
                                   n = Normalized(Cross(up, Vec3d(0, 0, 1)));
  DepthImage a, b, a2, b2;
  {
    const TriangleBvh bvh(mesh);
    DepthImageRenderer renderer(mesh, bvh, DepthImageOptions());
    renderer.RenderPair({p, up, n, 0.4}, &a, &b);
  }
  const auto R = testing_meshes::AxisAngle(Vec3d(1, -2, 0.5), 1.1);
  const double scale = 3.5;
  const Vec3d t(10, -4, 2);
  auto apply = [&](const Vec3d& v) {
    return Vec3d(R[0] * v.x + R[1] * v.y + R[2] * v.z,
                 R[3] * v.x + R[4] * v.y + R[5] * v.z,
                 R[6] * v.x + R[7] * v.y + R[8] * v.z);
  };
  TransformMesh(R, scale, t, &mesh);
  {
    const TriangleBvh bvh(mesh);
    DepthImageRenderer renderer(mesh, bvh, DepthImageOptions());
    renderer.RenderPair({apply(p) * scale + t, apply(up), apply(n), 0.4 * scale}, &a2, &b2);
  }
  for (std::size_t i = 0; i < a.depth.size(); ++i) {
    if (std::isinf(a.depth[i])) {
      EXPECT_TRUE(std::isinf(a2.depth[i]));
    } else {
      EXPECT_NEAR(a2.depth[i], scale * a.depth[i], 1e-3 * scale);
    }
    if (!std::isinf(b.depth[i])) {
      EXPECT_NEAR(b2.depth[i], scale * b.depth[i], 1e-3 * scale);
    }
  }
}

TEST(FinishDepthImageTest, FillsEmptyPixelsWithTheDeepestAndSmoothsTheCentre) {
  DepthImage image;
  image.size = 5;
  image.support_radius = 1;
  image.depth.assign(25, DepthImage::kEmpty);
  image.at(0, 0) = 0.5f;
  image.at(1, 2) = 1.5f;  // above the centre
  image.at(2, 2) = 0.0f;  // the centre, replaced
  ASSERT_TRUE(FinishDepthImage(&image));
  EXPECT_FLOAT_EQ(image.at(4, 4), 1.5f);
  EXPECT_FLOAT_EQ(image.at(0, 0), 0.5f);
  EXPECT_FLOAT_EQ(image.at(2, 2), 1.5f);  // mean of four neighbours, all 1.5
}

TEST(FinishDepthImageTest, RejectsAllEmptyImages) {
  DepthImage image;
  image.size = 3;
  image.depth.assign(9, DepthImage::kEmpty);
  EXPECT_FALSE(FinishDepthImage(&image));
}

TEST(DepthImageOptionsTest, DefaultsAreValidAndSizeIsChecked) {
  DepthImageOptions options;
  EXPECT_EQ(options.image_size, 21);  // the paper's I
  EXPECT_TRUE(options.Validate().ok());
  options.image_size = 20;
  EXPECT_FALSE(options.Validate().ok());
  options.image_size = 1;
  EXPECT_FALSE(options.Validate().ok());
}

}  // namespace
}  // namespace meshseek
