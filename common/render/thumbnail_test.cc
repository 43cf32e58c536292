#include "common/render/thumbnail.h"

#include <gtest/gtest.h>

#include <vector>

#include "common/geometry/test_meshes.h"
#include "common/render/png.h"
#include "common/render/view_renderer.h"

namespace meshseek {
namespace {

cv::Mat Decode(const std::string& png) {
  absl::StatusOr<cv::Mat> image = DecodePng(png);
  return image.ok() ? *image : cv::Mat();
}

TEST(ThumbnailTest, DefaultOptionsAreValid) { EXPECT_TRUE(ThumbnailOptions().Validate().ok()); }

TEST(ThumbnailTest, RejectsBadOptionsAndMeshes) {
  ThumbnailOptions options;
  options.size = 8;
  EXPECT_EQ(options.Validate().code(), absl::StatusCode::kInvalidArgument);
  options = {};
  options.eye = options.up * 3.0;  // looking straight down the up axis
  EXPECT_EQ(options.Validate().code(), absl::StatusCode::kInvalidArgument);
  options = {};
  options.colour.x = 2;
  EXPECT_EQ(options.Validate().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(RenderThumbnailPng(TriangleMesh{}).status().code(), absl::StatusCode::kInvalidArgument);
}

// A sphere fills the middle of the picture, opaque and lit, and leaves the
// corners transparent; the picture is the same every time.
TEST(ThumbnailTest, SphereIsOpaqueInTheMiddleAndTransparentInTheCorners) {
  ThumbnailOptions options;
  options.size = 64;
  const TriangleMesh sphere = testing_meshes::Icosphere(3);
  auto png = RenderThumbnailPng(sphere, options);
  ASSERT_TRUE(png.ok()) << png.status();
  const cv::Mat image = Decode(*png);
  ASSERT_EQ(image.type(), CV_8UC4);
  ASSERT_EQ(image.rows, 64);
  ASSERT_EQ(image.cols, 64);
  const cv::Vec4b centre = image.at<cv::Vec4b>(32, 32);
  EXPECT_EQ(centre[3], 255);
  EXPECT_GT(centre[0] + centre[1] + centre[2], 200);
  EXPECT_EQ(image.at<cv::Vec4b>(0, 0)[3], 0);
  EXPECT_EQ(image.at<cv::Vec4b>(63, 63)[3], 0);
  EXPECT_EQ(*RenderThumbnailPng(sphere, options), *png);
}

// Shading follows the key light (up and to the left): on a sphere the upper
// left is brighter than the lower right.
TEST(ThumbnailTest, KeyLightComesFromTheUpperLeft) {
  ThumbnailOptions options;
  options.size = 64;
  const cv::Mat image = Decode(*RenderThumbnailPng(testing_meshes::Icosphere(4), options));
  const cv::Vec4b upper_left = image.at<cv::Vec4b>(20, 20);
  const cv::Vec4b lower_right = image.at<cv::Vec4b>(44, 44);
  EXPECT_GT(upper_left[1], lower_right[1] + 20);
}

TEST(ViewRendererFacesTest, EveryCoveredPixelNamesItsTriangle) {
  ViewRenderOptions options;
  options.image_size = 32;
  options.record_faces = true;
  const TriangleMesh cube = testing_meshes::Cube();
  auto renderer = ViewRenderer::Create(cube, options);
  ASSERT_TRUE(renderer.ok());
  const ViewImage image = renderer->Render(Vec3d(0.3, 0.5, 1));
  ASSERT_EQ(image.face.size(), image.mask.size());
  for (std::size_t i = 0; i < image.mask.size(); ++i) {
    EXPECT_EQ(image.face[i] >= 0, image.mask[i] != 0);
    EXPECT_LT(image.face[i], static_cast<int32_t>(cube.triangles.size()));
  }
  options.record_faces = false;
  EXPECT_TRUE(ViewRenderer::Create(cube, options)->Render(Vec3d(0, 0, 1)).face.empty());
}

}  // namespace
}  // namespace meshseek
