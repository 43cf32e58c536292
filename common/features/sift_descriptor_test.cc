#include "common/features/sift_descriptor.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>

namespace meshseek {
namespace {

DepthImage RandomSmoothImage(int size, uint32_t seed) {
  std::mt19937 rng(seed);
  DepthImage image;
  image.size = size;
  image.support_radius = 1;
  image.depth.resize(size * size);
  const double a = rng() % 100 / 50.0 - 1, b = rng() % 100 / 50.0 - 1, c = rng() % 100 / 25.0;
  for (int r = 0; r < size; ++r) {
    for (int col = 0; col < size; ++col) {
      const double x = (col - size / 2) / double(size), y = (r - size / 2) / double(size);
      image.at(r, col) =
          static_cast<float>(1 + 0.5 * std::sin(c * x + a) * std::cos(3 * y + b) + 0.3 * x * y);
    }
  }
  return image;
}

DepthImage Turn180(const DepthImage& in) {
  DepthImage out = in;
  for (int r = 0; r < in.size; ++r) {
    for (int c = 0; c < in.size; ++c) out.at(r, c) = in.at(in.size - 1 - r, in.size - 1 - c);
  }
  return out;
}

DepthImage Turn90(const DepthImage& in) {  // counter-clockwise
  DepthImage out = in;
  for (int r = 0; r < in.size; ++r) {
    for (int c = 0; c < in.size; ++c) out.at(r, c) = in.at(c, in.size - 1 - r);
  }
  return out;
}

std::vector<uint8_t> DescribeOne(DepthSiftDescriber* describer, const DepthImage& image) {
  std::vector<uint8_t> out;
  EXPECT_EQ(describer->Describe(image, &out), 1);
  return out;
}

SiftDescriptorOptions UpAxisOptions() {
  SiftDescriptorOptions options;
  options.orientation = ImageOrientation::kUpAxis;
  return options;
}

TEST(SiftDescriptorTest, Rotate180IsAnInvolutivePermutation) {
  std::set<int> seen;
  for (int k = 0; k < kSiftDimension; ++k) {
    seen.insert(Rotate180Index(k));
    EXPECT_EQ(Rotate180Index(Rotate180Index(k)), k);
  }
  EXPECT_EQ(seen.size(), 128u);
}

TEST(SiftDescriptorTest, SymmetrisedDescriptorIgnoresTheUpAxisSign) {
  DepthSiftDescriber describer{UpAxisOptions()};
  for (uint32_t seed = 0; seed < 5; ++seed) {
    const DepthImage image = RandomSmoothImage(21, seed);
    const auto a = DescribeOne(&describer, image);
    const auto b = DescribeOne(&describer, Turn180(image));
    // Byte rounding and OpenCV's border handling allow a few units per bin.
    EXPECT_LT(DescriptorDistance(a.data(), b.data()), 12.0) << "seed " << seed;
  }
}

TEST(SiftDescriptorTest, PermutationMatchesOpenCvOnTurnedImage) {
  // Without symmetrisation, the descriptor of the turned image is the
  // permuted descriptor: this checks Rotate180Index against OpenCV's layout.
  SiftDescriptorOptions options = UpAxisOptions();
  options.symmetrize_180 = false;
  DepthSiftDescriber describer(options);
  const DepthImage image = RandomSmoothImage(21, 42);
  const auto a = DescribeOne(&describer, image);
  const auto b = DescribeOne(&describer, Turn180(image));
  uint8_t permuted[kSiftDimension];
  for (int k = 0; k < kSiftDimension; ++k) permuted[k] = a[Rotate180Index(k)];
  EXPECT_LT(DescriptorDistance(permuted, b.data()), 12.0);
  EXPECT_GT(DescriptorDistance(a.data(), b.data()),
            40.0);  // and the turn does change the raw descriptor
}

TEST(SiftDescriptorTest, DescriptorIsNormalisedAndDistinguishesImages) {
  DepthSiftDescriber describer{UpAxisOptions()};
  const auto a = DescribeOne(&describer, RandomSmoothImage(21, 1));
  const auto b = DescribeOne(&describer, RandomSmoothImage(21, 2));
  double sq = 0;
  for (int k = 0; k < kSiftDimension; ++k) sq += a[k] * double(a[k]);
  EXPECT_NEAR(std::sqrt(sq), 512.0, 10.0);
  EXPECT_GT(DescriptorDistance(a.data(), b.data()), 50.0);
}

TEST(SiftDescriptorTest, ContrastScaleDoesNotMatterWithStretch) {
  SiftDescriptorOptions options = UpAxisOptions();
  options.depth_to_gray = DepthToGray::kStretch;
  DepthSiftDescriber describer(options);
  DepthImage image = RandomSmoothImage(21, 3);
  DepthImage scaled = image;
  for (float& d : scaled.depth) d = 0.1f + 0.5f * d;
  const auto a = DescribeOne(&describer, image);
  const auto b = DescribeOne(&describer, scaled);
  EXPECT_LT(DescriptorDistance(a.data(), b.data()), 12.0);
}

TEST(SiftDescriptorTest, DominantOrientationFollowsTheImageRotation) {
  // A ramp rising towards +x (y up) has its gradient, and its single dominant
  // orientation, at 0 degrees; turned by 90 degrees counter-clockwise, at 90.
  DepthImage ramp = RandomSmoothImage(21, 0);
  for (int r = 0; r < 21; ++r) {
    for (int c = 0; c < 21; ++c) ramp.at(r, c) = 0.1f * c;
  }
  auto angles = DominantOrientations(ramp);
  ASSERT_EQ(angles.size(), 1u);
  EXPECT_NEAR(angles[0], 0.0, 5.0);
  angles = DominantOrientations(Turn90(ramp));
  ASSERT_EQ(angles.size(), 1u);
  EXPECT_NEAR(angles[0], 90.0, 5.0);

  // Descriptors in dominant mode do not change when the image turns: some
  // descriptor of the turned image matches some descriptor of the original.
  SiftDescriptorOptions options;
  options.orientation = ImageOrientation::kDominant;
  DepthSiftDescriber describer(options);
  for (uint32_t seed = 0; seed < 5; ++seed) {
    const DepthImage image = RandomSmoothImage(21, seed);
    std::vector<uint8_t> a, b;
    const int na = describer.Describe(image, &a), nb = describer.Describe(Turn90(image), &b);
    ASSERT_GE(na, 1);
    ASSERT_GE(nb, 1);
    double best = 1e9;
    for (int i = 0; i < na; ++i) {
      for (int j = 0; j < nb; ++j)
        best = std::min(best, DescriptorDistance(&a[i * 128], &b[j * 128]));
    }
    EXPECT_LT(best, 60.0) << "seed " << seed;  // unrelated descriptors are ~500 apart
  }
}

TEST(SiftDescriptorTest, OrientationsComeStrongestFirstAndCanBeCapped) {
  // A bowl (depth rising from the centre in every direction) has gradients
  // all round: several orientation peaks.
  DepthImage bowl = RandomSmoothImage(21, 0);
  for (int r = 0; r < 21; ++r) {
    for (int c = 0; c < 21; ++c)
      bowl.at(r, c) = 0.01f * ((r - 10) * (r - 10) + 1.3f * (c - 10) * (c - 10));
  }
  const std::vector<float> angles = DominantOrientations(bowl);
  ASSERT_GE(angles.size(), 2u);
  SiftDescriptorOptions options;
  options.orientation = ImageOrientation::kDominant;
  std::vector<uint8_t> all, capped;
  EXPECT_EQ(DepthSiftDescriber(options).Describe(bowl, &all), static_cast<int>(angles.size()));
  options.max_orientations = 1;
  EXPECT_EQ(DepthSiftDescriber(options).Describe(bowl, &capped), 1);
  // The one kept is the strongest, i.e. the first of the full set.
  EXPECT_TRUE(std::equal(capped.begin(), capped.end(), all.begin()));
}

TEST(NormalizeSiftDescriptorTest, ClipsAndScales) {
  float bins[kSiftDimension] = {};
  bins[0] = 100;  // one dominant bin is clipped at 0.2 then renormalised to 1
  bins[1] = 1;
  uint8_t out[kSiftDimension];
  NormalizeSiftDescriptor(bins, out);
  EXPECT_EQ(out[0], 255);  // 512 saturates
  EXPECT_GT(out[1], 0);
}

}  // namespace
}  // namespace meshseek
