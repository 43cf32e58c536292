#include "common/features/bf_dsift.h"

#include <gtest/gtest.h>

#include <algorithm>

#include "common/geometry/test_meshes.h"
#include "common/synth/shapes.h"

namespace meshseek {
namespace {

TEST(BfDsiftOptionsTest, DefaultsArePinnedAndValid) {
  const BfDsiftOptions options;
  EXPECT_TRUE(options.Validate().ok());
  EXPECT_EQ(options.view_level, 1);  // 42 views, the original's
  EXPECT_EQ(options.view_size, 128);
  EXPECT_EQ(options.points_per_view, 150);
  EXPECT_EQ(options.patch_radius, 0.05);
  EXPECT_EQ(options.patch_scales, 4);
  EXPECT_EQ(options.patch_image.image_size, 21);
  EXPECT_EQ(options.descriptor.orientation, ImageOrientation::kDominant);
  EXPECT_EQ(options.descriptor.max_orientations, 1);
}

TEST(BfDsiftOptionsTest, RejectsBadValuesWithTheirValue) {
  BfDsiftOptions options;
  options.patch_radius = 0.9;
  EXPECT_NE(options.Validate().message().find("patch_radius must be in (0, 0.5], got 0.9"),
            std::string::npos);
  options = BfDsiftOptions();
  options.view_level = 5;
  EXPECT_FALSE(options.Validate().ok());
}

// Small settings: 12 views, few points.
BfDsiftOptions Small() {
  BfDsiftOptions options;
  options.view_level = 0;
  options.view_size = 128;
  options.points_per_view = 40;
  options.patch_radius = 0.15;
  options.patch_scales = 1;
  return options;
}

// Mean over a's descriptors of the distance to the nearest of b's.
double Chamfer(const LocalFeatures& a, const LocalFeatures& b) {
  double sum = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    double best = 1e30;
    for (std::size_t j = 0; j < b.size(); ++j) {
      best = std::min(best, DescriptorDistance(a.descriptor(i), b.descriptor(j)));
    }
    sum += best;
  }
  return sum / static_cast<double>(a.size());
}

TriangleMesh Torus() { return MakeTorus(1.0, 0.35, 48, 24); }

TEST(BfDsiftTest, DescribesAboutThePointsAskedForPerView) {
  const auto f = ExtractBfDsift(Torus(), Small());
  ASSERT_TRUE(f.ok()) << f.status();
  EXPECT_EQ(f->dimension, static_cast<std::size_t>(kSiftDimension));
  EXPECT_EQ(f->descriptors.size(), f->size() * kSiftDimension);
  // 12 views x ~40 points, one or more orientations each.
  EXPECT_GT(f->size(), 12u * 25);
  EXPECT_LT(f->size(), 12u * 40 * 4);
  for (const Keypoint& k : f->keypoints) {
    EXPECT_GT(k.scale, 0);
    EXPECT_LT(Norm(Vec3d(k.position.x, k.position.y, k.position.z)), 1.4);  // on the torus
  }
}

// The views cover the sphere and SIFT fixes its own orientation, so a rotated,
// scaled and moved copy gives nearly the same set of descriptors: the mean
// nearest-descriptor distance to the copy is well under the one to a
// different shape (measured: about a third of it).
TEST(BfDsiftTest, IsNearlyInvariantToRotationScaleAndTranslation) {
  const TriangleMesh mesh = Torus();
  TriangleMesh moved = mesh;
  TransformMesh(testing_meshes::AxisAngle(Vec3d(0.3, -1, 2), 2.2), 7.5, Vec3d(-3, 40, 5), &moved);
  const TriangleMesh other = MakeBox(Vec3d(2, 1, 0.5), 0.1);
  const auto a = ExtractBfDsift(mesh, Small());
  const auto b = ExtractBfDsift(moved, Small());
  const auto c = ExtractBfDsift(other, Small());
  ASSERT_TRUE(a.ok() && b.ok() && c.ok());
  const double same = Chamfer(*a, *b), different = Chamfer(*a, *c);
  EXPECT_LT(same, 0.6 * different) << "same " << same << " different " << different;
}

TEST(BfDsiftTest, SoupsAndSeveralComponentsWorkAndRunsAreDeterministic) {
  TriangleMesh two = Torus();
  TriangleMesh box = MakeBox(Vec3d(1, 1, 1), 0.25);
  TransformMesh(testing_meshes::AxisAngle(Vec3d(0, 0, 1), 0), 1.0, Vec3d(3, 0, 0), &box);
  testing_meshes::Append(box, &two);
  const TriangleMesh soup = testing_meshes::ToSoup(two);
  const auto a = ExtractBfDsift(soup, Small());
  const auto b = ExtractBfDsift(soup, Small());
  ASSERT_TRUE(a.ok()) << a.status();
  EXPECT_EQ(a->descriptors, b->descriptors);
  // A soup renders exactly as its mesh: the same features.
  const auto m = ExtractBfDsift(two, Small());
  ASSERT_TRUE(m.ok());
  EXPECT_EQ(m->descriptors, a->descriptors);
}

// Views described on several threads (a query's extraction) give the same
// features in the same order.
TEST(BfDsiftTest, ThreadsChangeNothing) {
  const auto one = ExtractBfDsift(Torus(), Small());
  const auto three = ExtractBfDsift(Torus(), Small(), /*num_threads=*/3);
  ASSERT_TRUE(one.ok() && three.ok());
  EXPECT_EQ(one->descriptors, three->descriptors);
  ASSERT_EQ(one->size(), three->size());
  for (std::size_t i = 0; i < one->size(); ++i) {
    EXPECT_EQ(one->keypoints[i].position, three->keypoints[i].position) << i;
    EXPECT_EQ(one->keypoints[i].level, three->keypoints[i].level) << i;
  }
}

TEST(BfDsiftTest, RejectsMeshesWithoutExtent) {
  TriangleMesh point;
  point.vertices = {Vec3f(1, 1, 1), Vec3f(1, 1, 1), Vec3f(1, 1, 1)};
  point.triangles = {{0, 1, 2}};
  EXPECT_EQ(ExtractBfDsift(point, Small()).status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(ExtractBfDsift(TriangleMesh(), Small()).status().code(),
            absl::StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace meshseek
