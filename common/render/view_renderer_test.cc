#include "common/render/view_renderer.h"

#include <gtest/gtest.h>

#include <cmath>

#include "common/geometry/icosphere.h"
#include "common/geometry/test_meshes.h"

namespace meshseek {
namespace {

// The pixel centre (x, y) in view-window units: (u, v) in [-1, 1]^2 when
// window_scale is 1.
void WindowCoordinates(int x, int y, int n, double* u, double* v) {
  *u = (x + 0.5) / (0.5 * n) - 1.0;
  *v = 1.0 - (y + 0.5) / (0.5 * n);
}

TEST(ViewFrameTest, FramesAreOrthonormalAndRightHanded) {
  for (const Vec3d& d : IcosphereDirections(2)) {
    const ViewCamera f = CameraFor(d * 3.0);
    EXPECT_NEAR(Norm(f.direction), 1.0, 1e-12);
    EXPECT_NEAR(Norm(f.right), 1.0, 1e-12);
    EXPECT_NEAR(Norm(f.up), 1.0, 1e-12);
    EXPECT_NEAR(Dot(f.right, f.up), 0.0, 1e-12);
    EXPECT_NEAR(Dot(f.right, f.direction), 0.0, 1e-12);
    EXPECT_NEAR(Dot(f.up, f.direction), 0.0, 1e-12);
    EXPECT_NEAR(Distance(Cross(f.right, f.up), -f.direction), 0.0, 1e-12);
  }
}

TEST(IcosphereDirectionsTest, CountsAndUnitLength) {
  EXPECT_EQ(IcosphereDirections(0).size(), 12u);
  EXPECT_EQ(IcosphereDirections(1).size(), 42u);
  EXPECT_EQ(IcosphereDirections(2).size(), 162u);
  for (const Vec3d& d : IcosphereDirections(1)) EXPECT_NEAR(Norm(d), 1.0, 1e-12);
}

// A fine icosphere about an off-centre point: in every view the silhouette
// is the unit disc and the depth that of the sphere's near cap,
// (1 + sqrt(1 - r^2)) / 2 at window radius r.
TEST(ViewRendererTest, SphereMatchesAnalyticDepthFromEveryDirection) {
  TriangleMesh sphere = Icosphere(5, 2.5);
  for (Vec3f& v : sphere.vertices) v += Vec3f(10, -3, 7);
  ViewRenderOptions options;
  options.image_size = 64;
  auto renderer = ViewRenderer::Create(sphere, options);
  ASSERT_TRUE(renderer.ok()) << renderer.status();
  EXPECT_NEAR(renderer->sphere().radius, 2.5, 1e-3);
  for (const Vec3d& d : IcosphereDirections(1)) {
    const ViewImage image = renderer->Render(d);
    double worst = 0;
    for (int y = 0; y < image.size; ++y) {
      for (int x = 0; x < image.size; ++x) {
        double u, v;
        WindowCoordinates(x, y, image.size, &u, &v);
        const double r = std::sqrt(u * u + v * v);
        // Tessellation (level 5: chords 1.2e-3 of the radius inside the sphere).
        if (r < 0.99) {
          ASSERT_TRUE(image.Covered(x, y)) << "pixel " << x << "," << y << " r " << r;
          worst = std::max(worst, std::abs(image.DepthAt(x, y) - 0.5 * (1 + std::sqrt(1 - r * r))));
        } else if (r > 1.0) {
          ASSERT_FALSE(image.Covered(x, y)) << "pixel " << x << "," << y << " r " << r;
          EXPECT_EQ(image.DepthAt(x, y), 0.0f);
        }
      }
    }
    EXPECT_LT(worst, 2e-3) << "direction " << d;
  }
}

// A box [-1,2] x [-1,1] x [-1,1] seen along each axis: the near face's depth
// is exact and the silhouette is the face's rectangle.
TEST(ViewRendererTest, BoxMatchesAnalyticDepthAlongTheAxes) {
  TriangleMesh box = testing_meshes::Cube(1.0f);
  for (Vec3f& v : box.vertices) {
    if (v.x > 0) v.x = 2.0f;
  }
  ViewRenderOptions options;
  options.image_size = 96;
  options.window_scale = 1.25;
  auto renderer = ViewRenderer::Create(box, options);
  ASSERT_TRUE(renderer.ok()) << renderer.status();
  const Vec3d center = renderer->sphere().center;
  const double radius = renderer->sphere().radius;
  EXPECT_NEAR(center.x, 0.5, 1e-6);
  EXPECT_NEAR(radius, std::sqrt(1.5 * 1.5 + 2.0), 1e-6);
  const Vec3d lo(-1, -1, -1), hi(2, 1, 1);
  for (const Vec3d& d : {Vec3d(1, 0, 0), Vec3d(-1, 0, 0), Vec3d(0, 1, 0), Vec3d(0, 0, -1)}) {
    const ViewCamera frame = CameraFor(d);
    const ViewImage image = renderer->Render(frame);
    // The near face: the box's extreme along -d.
    double near = 0;
    for (int a = 0; a < 3; ++a) near += d[a] < 0 ? -d[a] * (hi[a] - center[a]) : -d[a] * (lo[a] - center[a]);
    const double expected = 0.5 * (1 + near / radius);
    int covered = 0, inside = 0;
    for (int y = 0; y < image.size; ++y) {
      for (int x = 0; x < image.size; ++x) {
        double u, v;
        WindowCoordinates(x, y, image.size, &u, &v);
        const Vec3d point = center + (frame.right * u + frame.up * v) * (radius * options.window_scale);
        // Inside the face's rectangle, with a margin of a pixel.
        const double margin = 2.5 * radius * options.window_scale / image.size;
        bool in = true, out = false;
        for (int a = 0; a < 3; ++a) {
          if (d[a] != 0) continue;
          in = in && point[a] > lo[a] + margin && point[a] < hi[a] - margin;
          out = out || point[a] < lo[a] - margin || point[a] > hi[a] + margin;
        }
        covered += image.Covered(x, y);
        if (in) {
          ++inside;
          ASSERT_TRUE(image.Covered(x, y));
          EXPECT_NEAR(image.DepthAt(x, y), expected, 1e-6);
        }
        if (out) {
          ASSERT_FALSE(image.Covered(x, y)) << x << "," << y;
        }
      }
    }
    EXPECT_GT(inside, 100);
    EXPECT_GE(covered, inside);
  }
}

TEST(ViewRendererTest, SoupsAndSeveralComponentsRenderTheSame) {
  TriangleMesh two = testing_meshes::Cube(0.5f);
  TriangleMesh other = testing_meshes::Icosphere(2, 0.7f);
  for (Vec3f& v : other.vertices) v += Vec3f(2, 0, 0);
  testing_meshes::Append(other, &two);
  ViewRenderOptions options;
  options.image_size = 48;
  auto mesh = ViewRenderer::Create(two, options);
  auto soup = ViewRenderer::Create(testing_meshes::ToSoup(two), options);
  ASSERT_TRUE(mesh.ok() && soup.ok());
  for (const Vec3d& d : IcosphereDirections(0)) {
    const ViewImage a = mesh->Render(d), b = soup->Render(d);
    EXPECT_EQ(a.mask, b.mask);
    EXPECT_EQ(a.depth, b.depth);
  }
}

// The silhouette path skips pixels and triangles already covered: the same
// mask, on meshes of many overlapping layers and triangles smaller than a
// pixel, framed whole or cut by the window's edges.
TEST(ViewRendererTest, SilhouetteIsTheMaskOfTheFullRender) {
  TriangleMesh layered = testing_meshes::LumpyBlob(4);
  TriangleMesh inner = testing_meshes::Icosphere(3, 0.6f);
  testing_meshes::Append(inner, &layered);
  testing_meshes::Append(testing_meshes::Cube(0.3f), &layered);
  for (const int size : {16, 64, 128}) {
    for (const double window : {1.0, 0.4}) {
      ViewRenderOptions options;
      options.image_size = size;
      options.window_scale = window;
      for (const TriangleMesh& mesh : {layered, testing_meshes::ToSoup(layered)}) {
        auto renderer = ViewRenderer::Create(mesh, options);
        ASSERT_TRUE(renderer.ok()) << renderer.status();
        for (const Vec3d& d : IcosphereDirections(1)) {
          const ViewCamera camera = CameraFor(d);
          const std::vector<uint8_t> silhouette = renderer->RenderSilhouette(camera);
          EXPECT_EQ(silhouette, renderer->Render(camera).mask)
              << "size " << size << ", window " << window;
        }
      }
    }
  }
}

TEST(ViewRendererTest, RefusesWhatCannotBeFramed) {
  EXPECT_FALSE(ViewRenderer::Create(TriangleMesh(), {}).ok());
  TriangleMesh point;
  point.vertices = {{1, 1, 1}, {1, 1, 1}, {1, 1, 1}};
  point.triangles = {{0, 1, 2}};
  EXPECT_FALSE(ViewRenderer::Create(point, {}).ok());
  ViewRenderOptions bad;
  bad.image_size = 3;
  EXPECT_FALSE(ViewRenderer::Create(testing_meshes::Cube(), bad).ok());
  bad = {};
  bad.window_scale = 0;
  EXPECT_FALSE(ViewRenderer::Create(testing_meshes::Cube(), bad).ok());
}

}  // namespace
}  // namespace meshseek
