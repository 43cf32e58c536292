#include "common/features/dld_sift.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "common/geometry/test_meshes.h"

namespace meshseek {
namespace {

using testing_meshes::LumpyBlob;

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

TEST(DldSiftTest, TwoFeaturesPerPointOnAClosedSurfaceWithTheUpAxis) {
  DldSiftOptions options;
  options.num_points = 256;
  options.descriptor.orientation = ImageOrientation::kUpAxis;
  auto features = ExtractDldSift(LumpyBlob(), options);
  ASSERT_TRUE(features.ok()) << features.status();
  EXPECT_EQ(features->size(), 512u);
  EXPECT_EQ(features->descriptors.size(), 512u * kSiftDimension);
  for (const Keypoint& k : features->keypoints) {
    EXPECT_NEAR(Norm(Vec3d(k.view)), 1.0, 1e-5);
    EXPECT_NEAR(Dot(Vec3d(k.view), Vec3d(k.up)), 0.0, 1e-5);
  }
}

TEST(DldSiftTest, AtLeastTwoFeaturesPerPointWithDominantOrientations) {
  DldSiftOptions options;
  options.num_points = 256;
  options.descriptor.orientation = ImageOrientation::kDominant;
  auto features = ExtractDldSift(LumpyBlob(), options);
  ASSERT_TRUE(features.ok()) << features.status();
  EXPECT_GE(features->size(), 512u);
  EXPECT_LE(features->size(), 512u * 4);
  EXPECT_EQ(features->descriptors.size(), features->size() * kSiftDimension);
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
  // Points described on several threads (a query's extraction): the same.
  auto threaded = ExtractDldSift(mesh, options, /*num_threads=*/3);
  ASSERT_TRUE(threaded.ok());
  EXPECT_EQ(a->descriptors, threaded->descriptors);
}

// Descriptors of one feature point, grouped by its position (features come
// out point by point).
std::vector<std::vector<const uint8_t*>> GroupByPoint(const LocalFeatures& f) {
  std::vector<std::vector<const uint8_t*>> groups;
  for (std::size_t i = 0; i < f.size(); ++i) {
    if (i == 0 || f.keypoints[i].position != f.keypoints[i - 1].position) groups.emplace_back();
    groups.back().push_back(f.descriptor(i));
  }
  return groups;
}

// Rotation, uniform scale and translation of the model leave the descriptors
// nearly unchanged: the sampler, the enclosing sphere and the frames are all
// similarity-covariant, so point i of one run matches point i of the other;
// the views of a point may swap (normal sign), the up axis may flip (absorbed
// by the 180-degree sum) and, with dominant orientations, a peak near the 80 %
// threshold may come or go. Tolerance: the mean distance from each descriptor
// to the nearest descriptor of the same point in the other run is under 5 %
// of the mean distance between descriptors of unrelated points.
void ExpectSimilarityInvariance(ImageOrientation orientation) {
  DldSiftOptions options;
  options.num_points = 200;
  options.descriptor.orientation = orientation;
  const TriangleMesh mesh = LumpyBlob();
  TriangleMesh moved = mesh;
  TransformMesh(testing_meshes::AxisAngle(Vec3d(0.3, -1, 2), 2.2), 7.5, Vec3d(-3, 40, 5), &moved);
  auto a = ExtractDldSift(mesh, options);
  auto b = ExtractDldSift(moved, options);
  ASSERT_TRUE(a.ok() && b.ok());
  const auto ga = GroupByPoint(*a), gb = GroupByPoint(*b);
  ASSERT_EQ(ga.size(), gb.size());
  double matched = 0, unrelated = 0;
  std::size_t count = 0;
  for (std::size_t p = 0; p < ga.size(); ++p) {
    for (const uint8_t* d : ga[p]) {
      double best = 1e30;
      for (const uint8_t* e : gb[p]) best = std::min(best, DescriptorDistance(d, e));
      matched += best;
      unrelated += DescriptorDistance(d, gb[(p + 50) % gb.size()][0]);
      ++count;
    }
  }
  EXPECT_LT(matched / count, 0.05 * unrelated / count)
      << "matched " << matched / count << " unrelated " << unrelated / count;
}

TEST(DldSiftTest, UpAxisDescriptorsAreInvariantToSimilarityTransforms) {
  ExpectSimilarityInvariance(ImageOrientation::kUpAxis);
}

TEST(DldSiftTest, DominantOrientationDescriptorsAreInvariantToSimilarityTransforms) {
  ExpectSimilarityInvariance(ImageOrientation::kDominant);
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
