#include "common/features/dld_sift.h"

#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>

#include "common/geometry/test_meshes.h"

namespace meshseek {
namespace {

// A lumpy closed surface with no symmetry.
TriangleMesh LumpyBlob(int levels = 3) {
  TriangleMesh mesh = testing_meshes::Icosphere(levels, 1.0f);
  for (Vec3f& v : mesh.vertices) {
    const float bump = 1.0f + 0.25f * std::sin(3 * v.x + 1) * std::cos(2 * v.y) + 0.15f * v.z * v.x;
    v = Vec3f(1.6f * v.x * bump, v.y * bump, 0.7f * v.z * bump);
  }
  return mesh;
}

double L2(const uint8_t* a, const uint8_t* b) {
  double s = 0;
  for (int k = 0; k < kSiftDimension; ++k) s += (a[k] - b[k]) * double(a[k] - b[k]);
  return std::sqrt(s);
}

TEST(DldSiftOptionsTest, DefaultsArePinnedAndValid) {
  const DldSiftOptions options;
  EXPECT_EQ(options.num_points, 1024);  // the paper's N_DLD
  EXPECT_EQ(options.depth_image.image_size, 21);
  EXPECT_TRUE(options.two_views);
  EXPECT_TRUE(options.Validate().ok());
}

TEST(DldSiftOptionsTest, RejectsBadValuesWithTheirValue) {
  DldSiftOptions options;
  options.scale = 0;
  EXPECT_NE(options.Validate().message().find("got 0"), absl::string_view::npos);
  options = DldSiftOptions();
  options.num_points = -3;
  EXPECT_NE(options.Validate().message().find("got -3"), absl::string_view::npos);
  options = DldSiftOptions();
  options.depth_image.image_size = 4;
  EXPECT_FALSE(options.Validate().ok());
}

TEST(DldSiftTest, TwoFeaturesPerPointOnAClosedSurface) {
  DldSiftOptions options;
  options.num_points = 256;
  auto features = ExtractDldSift(LumpyBlob(), options);
  ASSERT_TRUE(features.ok()) << features.status();
  EXPECT_EQ(features->size(), 512u);
  EXPECT_EQ(features->descriptors.size(), 512u * kSiftDimension);
  for (const Keypoint& k : features->keypoints) {
    EXPECT_NEAR(Norm(Vec3d(k.view)), 1.0, 1e-5);
    EXPECT_NEAR(Dot(Vec3d(k.view), Vec3d(k.up)), 0.0, 1e-5);
  }
}

TEST(DldSiftTest, IsDeterministicAndIgnoresTessellationSharing) {
  DldSiftOptions options;
  options.num_points = 128;
  const TriangleMesh mesh = LumpyBlob();
  auto a = ExtractDldSift(mesh, options);
  auto b = ExtractDldSift(mesh, options);
  auto soup = ExtractDldSift(testing_meshes::ToSoup(mesh), options);
  ASSERT_TRUE(a.ok() && b.ok() && soup.ok());
  EXPECT_EQ(a->descriptors, b->descriptors);
  // The same triangles as a polygon soup: the dense method does not care.
  EXPECT_EQ(a->descriptors, soup->descriptors);
}

// Rotation, uniform scale and translation of the model leave the descriptors
// nearly unchanged: the sampler, the enclosing sphere and the frames are all
// similarity-covariant, so point i of one run matches point i of the other;
// the pair of views of a point may swap (normal sign) and the up axis may flip
// (absorbed by the 180-degree sum). Tolerance: the mean distance between
// matched descriptors is under 5 % of the mean distance between unrelated ones.
TEST(DldSiftTest, DescriptorsAreInvariantToSimilarityTransforms) {
  DldSiftOptions options;
  options.num_points = 200;
  const TriangleMesh mesh = LumpyBlob();
  TriangleMesh moved = mesh;
  TransformMesh(testing_meshes::AxisAngle(Vec3d(0.3, -1, 2), 2.2), 7.5, Vec3d(-3, 40, 5), &moved);
  auto a = ExtractDldSift(mesh, options);
  auto b = ExtractDldSift(moved, options);
  ASSERT_TRUE(a.ok() && b.ok());
  ASSERT_EQ(a->size(), b->size());
  double matched = 0, unrelated = 0;
  for (std::size_t i = 0; i + 1 < a->size(); i += 2) {
    const double same = L2(a->descriptor(i), b->descriptor(i)) + L2(a->descriptor(i + 1), b->descriptor(i + 1));
    const double swapped = L2(a->descriptor(i), b->descriptor(i + 1)) + L2(a->descriptor(i + 1), b->descriptor(i));
    matched += std::min(same, swapped) / 2;
    unrelated += L2(a->descriptor(i), b->descriptor((i + 50) % b->size()));
  }
  const double pairs = a->size() / 2.0;
  EXPECT_LT(matched / pairs, 0.05 * unrelated / pairs)
      << "matched " << matched / pairs << " unrelated " << unrelated / pairs;
}

TEST(DldSiftTest, RejectsInvalidMeshes) {
  TriangleMesh bad = LumpyBlob(1);
  bad.vertices[0].x = NAN;
  auto features = ExtractDldSift(bad, DldSiftOptions());
  ASSERT_FALSE(features.ok());
  EXPECT_NE(features.status().message().find("non-finite"), absl::string_view::npos);
}

}  // namespace
}  // namespace meshseek
