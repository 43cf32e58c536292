#include "common/features/lsf.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

#include "common/geometry/test_meshes.h"
#include "common/synth/shapes.h"

namespace meshseek {
namespace {

using testing_meshes::LumpyBlob;

// Fast options for tests: fewer centres, the default design otherwise.
LsfOptions TestOptions() {
  LsfOptions options;
  options.num_points = 256;
  return options;
}

double SquaredDistance(const LocalFeatures& a,
                       std::size_t i,
                       const LocalFeatures& b,
                       std::size_t j) {
  double sum = 0;
  for (std::size_t k = 0; k < a.dimension; ++k) {
    const double d = double(a.descriptor(i)[k]) - b.descriptor(j)[k];
    sum += d * d;
  }
  return sum;
}

// Mean over `query`'s descriptors of the distance to the nearest descriptor of
// `reference`: small when every local feature of the query has a twin in the
// reference, whatever their order.
double MeanNearestDistance(const LocalFeatures& query, const LocalFeatures& reference) {
  double total = 0;
  for (std::size_t i = 0; i < query.size(); ++i) {
    double best = std::numeric_limits<double>::infinity();
    for (std::size_t j = 0; j < reference.size(); ++j) {
      best = std::min(best, SquaredDistance(query, i, reference, j));
    }
    total += std::sqrt(best);
  }
  return total / query.size();
}

LocalFeatures Extract(const TriangleMesh& mesh, const LsfOptions& options = TestOptions()) {
  auto features = ExtractLsf(mesh, options);
  EXPECT_TRUE(features.ok()) << features.status();
  return features.ok() ? *std::move(features) : LocalFeatures{};
}

TEST(LsfOptionsTest, DefaultsArePinnedAndValid) {
  const LsfOptions options;
  EXPECT_EQ(options.num_points, 1024);
  EXPECT_DOUBLE_EQ(options.scale, 0.3);
  EXPECT_EQ(options.extra_scales, std::vector<double>{0.6});
  EXPECT_EQ(options.samples_per_support, 96);
  EXPECT_EQ(options.min_samples, 2048);
  EXPECT_EQ(options.max_samples, 100000);
  EXPECT_EQ(options.min_support_samples, 8);
  EXPECT_EQ(options.max_support_samples, 192);
  EXPECT_EQ(options.relations, LsfOptions::Relations::kCentre);
  EXPECT_EQ(options.layout, LsfOptions::Layout::kFullJoint);
  EXPECT_EQ(options.distance_bins, 4);
  EXPECT_EQ(options.angle_bins, 6);
  EXPECT_TRUE(options.soft_binning);
  EXPECT_FALSE(options.pca_centre_normal);
  EXPECT_TRUE(options.root);
  EXPECT_EQ(options.Dimension(), 864u);
  EXPECT_TRUE(options.Validate().ok());
}

TEST(LsfOptionsTest, DimensionFollowsTheLayoutAndRelations) {
  LsfOptions options;
  options.distance_bins = 4;
  options.angle_bins = 6;
  options.relations = LsfOptions::Relations::kPairs;  // both line angles pooled
  options.layout = LsfOptions::Layout::kConcatenated;
  EXPECT_EQ(options.Dimension(), 4u + 2 * 6);
  options.layout = LsfOptions::Layout::kDistanceJoint;
  EXPECT_EQ(options.Dimension(), 2u * 4 * 6);
  options.layout = LsfOptions::Layout::kFullJoint;
  EXPECT_EQ(options.Dimension(), 4u * 6 * 6 * 6);
  options.relations = LsfOptions::Relations::kCentre;  // the centre's and the sample's apart
  options.layout = LsfOptions::Layout::kConcatenated;
  EXPECT_EQ(options.Dimension(), 4u + 3 * 6);
  options.layout = LsfOptions::Layout::kDistanceJoint;
  EXPECT_EQ(options.Dimension(), 3u * 4 * 6);
  options.relations = LsfOptions::Relations::kBoth;
  EXPECT_EQ(options.Dimension(), 2u * 4 * 6 + 3u * 4 * 6);
}

TEST(LsfOptionsTest, RejectsBadValuesWithTheirValue) {
  LsfOptions options;
  options.scale = 0;
  EXPECT_NE(options.Validate().message().find("got 0"), absl::string_view::npos);
  options = LsfOptions();
  options.num_points = -3;
  EXPECT_NE(options.Validate().message().find("got -3"), absl::string_view::npos);
  options = LsfOptions();
  options.max_support_samples = 4;  // below min_support_samples
  EXPECT_EQ(options.Validate().code(), absl::StatusCode::kInvalidArgument);
  options = LsfOptions();
  options.layout = LsfOptions::Layout::kFullJoint;
  options.distance_bins = 16;
  options.angle_bins = 16;  // 16 x 16^3 = 65536 bytes, past kMaxDescriptorDimension
  EXPECT_NE(options.Validate().message().find("got 65536"), absl::string_view::npos);
}

TEST(LsfTest, OneFeaturePerCentreAndRadiusOnAClosedSurface) {
  const LocalFeatures features = Extract(LumpyBlob());
  ASSERT_EQ(features.size(), 2 * 256u);  // scale and the one extra scale
  EXPECT_EQ(features.dimension, 864u);
  EXPECT_EQ(features.descriptors.size(), 2 * 256u * 864);
  for (const Keypoint& k : features.keypoints) {
    EXPECT_NEAR(Norm(Vec3d(k.view)), 1.0, 1e-5);
    EXPECT_NEAR(Norm(Vec3d(k.up)), 1.0, 1e-5);
    EXPECT_NEAR(Dot(Vec3d(k.view), Vec3d(k.up)), 0.0, 1e-5);
  }
  // The first 256 at scale (level 0), the next 256 at the extra scale.
  EXPECT_EQ(features.keypoints[255].level, 0);
  EXPECT_EQ(features.keypoints[256].level, 1);
  EXPECT_NEAR(features.keypoints[256].scale, 2 * features.keypoints[0].scale, 1e-5);
  bool differ = false;
  for (std::size_t i = 1; i < features.size() && !differ; ++i) {
    differ = SquaredDistance(features, 0, features, i) > 0;
  }
  EXPECT_TRUE(differ);
}

TEST(LsfTest, InvariantToRotationScaleAndTranslation) {
  const TriangleMesh blob = LumpyBlob();
  TriangleMesh moved = blob;
  TransformMesh(testing_meshes::AxisAngle({1, 2, -0.5}, 1.1), 3.7, {5, -2, 11}, &moved);
  const LocalFeatures original = Extract(blob);
  const LocalFeatures copy = Extract(moved);
  const LocalFeatures torus = Extract(MakeTorus(1.0, 0.35, 48, 24));
  const LocalFeatures box = Extract(MakeBox({2.0, 1.2, 0.8}, 0.1));
  const double same = MeanNearestDistance(copy, original);
  const double other =
      std::min(MeanNearestDistance(torus, original), MeanNearestDistance(box, original));
  std::printf("LSF nearest-descriptor distance: moved copy %.2f, other shapes %.2f (bytes, L2)\n",
              same,
              other);
  EXPECT_LT(same, 0.2 * other);
}

TEST(LsfTest, PolygonSoupsAndFlippedTrianglesGiveTheSameFeatures) {
  const TriangleMesh mesh = LumpyBlob();
  const LocalFeatures welded = Extract(mesh);
  // Every triangle with its own vertices (duplicates everywhere).
  EXPECT_EQ(Extract(testing_meshes::ToSoup(mesh)).descriptors, welded.descriptors);
  // Every other triangle flipped: face normals change sign, the relations
  // (absolute cosines) do not. The corner order moves the samples within each
  // flipped triangle, so the features match within sampling noise only.
  TriangleMesh flipped = testing_meshes::ToSoup(mesh);
  for (std::size_t t = 0; t < flipped.triangles.size(); t += 2) {
    std::swap(flipped.triangles[t][1], flipped.triangles[t][2]);
  }
  const double same = MeanNearestDistance(Extract(flipped), welded);
  const double other = MeanNearestDistance(Extract(MakeTorus(1.0, 0.35, 48, 24)), welded);
  std::printf("LSF nearest-descriptor distance: flipped soup %.2f, torus %.2f\n", same, other);
  EXPECT_LT(same, 0.5 * other);
}

TEST(LsfTest, MultiComponentModelsDoNotDependOnComponentOrder) {
  TriangleMesh torus = MakeTorus(1.0, 0.35, 48, 24);
  TriangleMesh blob = LumpyBlob();
  TransformMesh(testing_meshes::AxisAngle({0, 0, 1}, 0), 1.0, {3.5, 0, 0}, &blob);
  TriangleMesh ab, ba;
  testing_meshes::Append(torus, &ab);
  testing_meshes::Append(blob, &ab);
  testing_meshes::Append(blob, &ba);
  testing_meshes::Append(torus, &ba);
  const LocalFeatures first = Extract(ab);
  const LocalFeatures second = Extract(ba);
  EXPECT_EQ(first.size(), 2 * 256u);
  EXPECT_EQ(second.size(), 2 * 256u);
  // The sampler visits triangles in file order, so the samples differ; the
  // features must still match feature for feature.
  const double same = MeanNearestDistance(second, first);
  const double other = MeanNearestDistance(Extract(MakeBox({2.0, 1.2, 0.8}, 0.1)), first);
  std::printf(
      "LSF nearest-descriptor distance: reordered components %.2f, box %.2f\n", same, other);
  EXPECT_LT(same, 0.5 * other);
}

TEST(LsfTest, IsDeterministic) {
  const TriangleMesh mesh = LumpyBlob();
  const LocalFeatures a = Extract(mesh);
  const LocalFeatures b = Extract(mesh);
  EXPECT_EQ(a.descriptors, b.descriptors);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i)
    EXPECT_EQ(a.keypoints[i].position, b.keypoints[i].position);
}

TEST(LsfTest, PairRelationsAndOtherLayoutsWork) {
  LsfOptions options = TestOptions();
  options.relations = LsfOptions::Relations::kPairs;
  options.layout = LsfOptions::Layout::kDistanceJoint;
  options.distance_bins = 8;
  options.angle_bins = 8;
  options.max_support_samples = 64;  // pairs cost its square
  const LocalFeatures pairs = Extract(LumpyBlob(), options);
  EXPECT_EQ(pairs.dimension, 128u);
  EXPECT_EQ(pairs.descriptors.size(), pairs.size() * 128);
  options.relations = LsfOptions::Relations::kBoth;
  options.layout = LsfOptions::Layout::kConcatenated;
  options.soft_binning = false;
  const LocalFeatures both = Extract(LumpyBlob(), options);
  EXPECT_EQ(both.dimension, (8u + 2 * 8) + (8u + 3 * 8));
  EXPECT_EQ(both.descriptors.size(), both.size() * both.dimension);
}

TEST(LsfTest, ExtraScalesAddOneFeaturePerCentreEach) {
  LsfOptions options = TestOptions();
  options.extra_scales = {options.scale * 2};
  const LocalFeatures features = Extract(LumpyBlob(), options);
  ASSERT_EQ(features.size(), 512u);
  EXPECT_EQ(features.keypoints[0].level, 0);
  EXPECT_EQ(features.keypoints[511].level, 1);
  EXPECT_NEAR(features.keypoints[511].scale, 2 * features.keypoints[0].scale, 1e-5);
  options.extra_scales = {3.0};
  EXPECT_NE(options.Validate().message().find("got 3"), absl::string_view::npos);
}

TEST(LsfTest, MeshesWithoutAreaAreInvalidArguments) {
  TriangleMesh flat;
  flat.vertices = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
  flat.triangles = {{0, 1, 2}, {0, 0, 1}};
  auto features = ExtractLsf(flat, TestOptions());
  EXPECT_EQ(features.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(features.status().message().find("area"), absl::string_view::npos) << features.status();
  EXPECT_EQ(ExtractLsf(TriangleMesh{}, TestOptions()).status().code(),
            absl::StatusCode::kInvalidArgument);
  LsfOptions bad = TestOptions();
  bad.angle_bins = 0;
  EXPECT_EQ(ExtractLsf(LumpyBlob(), bad).status().code(), absl::StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace meshseek
