#include "common/features/sift_descriptor.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>
#include <random>
#include <set>
#include <string>

#include "common/features/depth_image.h"
#include "common/features/local_depth_sift.h"
#include "common/geometry/enclosing_sphere.h"
#include "common/geometry/mesh_io.h"
#include "common/geometry/point_grid.h"
#include "common/geometry/surface_sampler.h"
#include "common/geometry/triangle_bvh.h"
#include "common/synth/synthetic_classes.h"

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
    // Byte rounding and the border handling allow a few units per bin.
    EXPECT_LT(DescriptorDistance(a.data(), b.data()), 12.0) << "seed " << seed;
  }
}

TEST(SiftDescriptorTest, PermutationMatchesTheTurnedImage) {
  // Without symmetrisation, the descriptor of the turned image is the
  // permuted descriptor: this checks Rotate180Index against the bin layout
  // (which OpenCvReference below checks against OpenCV's).
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

// The descriptors as they were computed before this code replaced OpenCV:
// cv::SIFT::compute on the 8-bit image, one keypoint of size I / 6 at the
// centre per orientation (OpenCV's angles are clockwise), and the result
// summed with its 180-degree turn (kUpAxis) and normalised again.
int OpenCvReference(const DepthImage& image,
                    const SiftDescriptorOptions& options,
                    const std::vector<float>& thetas,
                    std::vector<uint8_t>* out) {
  const int size = image.size;
  cv::Mat gray(size, size, CV_8U);
  float lo = 0, hi = 2 * image.support_radius;
  if (options.depth_to_gray == DepthToGray::kStretch) {
    const auto [mn, mx] = std::minmax_element(image.depth.begin(), image.depth.end());
    lo = *mn;
    hi = *mx;
  }
  const float scale = hi > lo ? 255.0f / (hi - lo) : 0.0f;
  for (int r = 0; r < size; ++r) {
    for (int c = 0; c < size; ++c) {
      gray.at<uint8_t>(r, c) =
          static_cast<uint8_t>(std::clamp(std::lround((image.at(r, c) - lo) * scale), 0L, 255L));
    }
  }
  const float centre = static_cast<float>(size / 2);
  std::vector<cv::KeyPoint> keypoints;
  for (const float theta : thetas) {
    const float angle = 360.0f - theta;
    keypoints.emplace_back(centre, centre, size / 6.0f, angle >= 360.0f ? 0.0f : angle);
  }
  cv::Mat descriptors;
  cv::SIFT::create(0, 3, 0.04, 10, options.blur_sigma)->compute(gray, keypoints, descriptors);
  const bool sum_turned =
      options.orientation == ImageOrientation::kUpAxis && options.symmetrize_180;
  float bins[kSiftDimension];
  for (int row = 0; row < descriptors.rows; ++row) {
    const float* raw = descriptors.ptr<float>(row);
    for (int k = 0; k < kSiftDimension; ++k)
      bins[k] = raw[k] + (sum_turned ? raw[Rotate180Index(k)] : 0.0f);
    const std::size_t at = out->size();
    out->resize(at + kSiftDimension);
    NormalizeSiftDescriptor(bins, out->data() + at);
  }
  return descriptors.rows;
}

// DominantOrientations as it was, with std::atan2 and std::exp per pixel.
std::vector<float> ReferenceDominantOrientations(const DepthImage& image) {
  constexpr int kBins = 36;
  const int size = image.size;
  const float centre = (size - 1) / 2.0f;
  const float sigma = 0.4f * size;
  float hist[kBins] = {};
  for (int r = 1; r + 1 < size; ++r) {
    for (int c = 1; c + 1 < size; ++c) {
      const float dx = image.at(r, c + 1) - image.at(r, c - 1);
      const float dy = image.at(r - 1, c) - image.at(r + 1, c);
      const float magnitude = std::sqrt(dx * dx + dy * dy);
      if (magnitude <= 0) continue;
      const float d2 = (r - centre) * (r - centre) + (c - centre) * (c - centre);
      float angle = std::atan2(dy, dx) * static_cast<float>(180.0 / M_PI);
      if (angle < 0) angle += 360.0f;
      const int bin = static_cast<int>(angle * kBins / 360.0f) % kBins;
      hist[bin] += magnitude * std::exp(-d2 / (2 * sigma * sigma));
    }
  }
  float smooth[kBins];
  for (int b = 0; b < kBins; ++b) {
    auto h = [&](int k) { return hist[(k + kBins) % kBins]; };
    smooth[b] = (h(b - 2) + h(b + 2)) / 16 + (h(b - 1) + h(b + 1)) * 4 / 16 + h(b) * 6 / 16;
  }
  const float highest = *std::max_element(smooth, smooth + kBins);
  std::vector<std::pair<float, float>> peaks;
  if (!(highest > 0)) return {};
  for (int b = 0; b < kBins; ++b) {
    const float left = smooth[(b + kBins - 1) % kBins], right = smooth[(b + 1) % kBins];
    if (smooth[b] > left && smooth[b] > right && smooth[b] >= 0.8f * highest) {
      const float offset = 0.5f * (left - right) / (left - 2 * smooth[b] + right);
      peaks.emplace_back(smooth[b], std::fmod((b + 0.5f + offset) * 10.0f + 360.0f, 360.0f));
    }
  }
  std::stable_sort(
      peaks.begin(), peaks.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  std::vector<float> angles;
  for (const auto& peak : peaks) angles.push_back(peak.second);
  return angles;
}

// Finished depth images of a model as DLD-SIFT renders them: `points`
// surface samples, support s = 0.2 of the enclosing radius, weighted PCA
// frame of a dense sample, front and back views.
std::vector<DepthImage> DldImages(const TriangleMesh& mesh, int points) {
  std::vector<DepthImage> images;
  const auto sphere = MinimumEnclosingSphere(mesh);
  const auto centres = SampleSurface(mesh, points);
  const auto dense = SampleSurface(mesh, 20000);
  if (!sphere.ok() || !centres.ok() || !dense.ok()) return images;
  const double s = 0.2 * sphere->radius;
  const PointGrid grid(dense->positions, static_cast<float>(s));
  const TriangleBvh bvh(mesh);
  DepthImageRenderer renderer(mesh, bvh, DepthImageOptions());
  std::vector<uint32_t> support;
  for (const Vec3f& p : centres->positions) {
    const auto axes = SupportAxes(dense->positions, grid, p, s, true, &support);
    if (!axes) continue;
    DepthImage front, back;
    renderer.RenderPair({Vec3d(p), axes->axes[0], axes->axes[2], s}, &front, &back);
    for (DepthImage* image : {&front, &back}) {
      if (FinishDepthImage(image)) images.push_back(*image);
    }
  }
  return images;
}

// Depth images for the comparisons: every synthetic class, and the first
// models of $MESHSEEK_SIFT_COMPARE_DIR if set (e.g. McGill's, to check on real
// data; the result is printed).
std::vector<DepthImage> ComparisonImages() {
  std::vector<DepthImage> images;
  SyntheticShapeParams params;
  params.density = 3;
  for (const SyntheticClass& c : SyntheticClasses()) {
    SynthRandom rng(HashName(c.name));
    const auto mesh = c.build(params, &rng);
    if (!mesh.ok()) continue;
    const std::vector<DepthImage> more = DldImages(*mesh, 100);
    images.insert(images.end(), more.begin(), more.end());
  }
  if (const char* dir = std::getenv("MESHSEEK_SIFT_COMPARE_DIR")) {
    std::vector<std::string> paths;
    for (const auto& entry : std::filesystem::recursive_directory_iterator(dir)) {
      if (entry.is_regular_file() && MeshFormatFromPath(entry.path().string()).ok())
        paths.push_back(entry.path().string());
    }
    std::sort(paths.begin(), paths.end());
    paths.resize(std::min<std::size_t>(paths.size(), 20));
    for (const std::string& path : paths) {
      const auto mesh = ReadMesh(path);
      if (!mesh.ok()) continue;
      const std::vector<DepthImage> more = DldImages(*mesh, 200);
      images.insert(images.end(), more.begin(), more.end());
    }
  }
  return images;
}

const std::vector<DepthImage>& Images() {
  static const std::vector<DepthImage> images = ComparisonImages();
  return images;
}

TEST(SiftDescriptorTest, DominantOrientationsMatchTheExactComputation) {
  // The polynomial atan2 moves a gradient across a histogram bin boundary
  // only when it lies within about 0.01 degree of it: rarely, and then the
  // peak moves by a fraction of its 10-degree bin.
  int same = 0, same_count = 0;
  double worst = 0;
  for (const DepthImage& image : Images()) {
    // As sets: two peaks of nearly equal height may swap places.
    std::vector<float> fast = DominantOrientations(image);
    std::vector<float> exact = ReferenceDominantOrientations(image);
    if (fast.size() != exact.size()) continue;
    std::sort(fast.begin(), fast.end());
    std::sort(exact.begin(), exact.end());
    ++same_count;
    double difference = 0;
    for (std::size_t k = 0; k < fast.size(); ++k) {
      const double d = std::abs(fast[k] - exact[k]);
      difference = std::max(difference, std::min(d, 360 - d));
    }
    worst = std::max(worst, difference);
    same += difference < 0.01;
  }
  const double n = static_cast<double>(Images().size());
  std::cout << Images().size() << " images: orientation sets equal (within 0.01 degree) "
            << same / n << ", same number of orientations " << same_count / n
            << ", largest difference among those " << worst << " degrees\n";
  ASSERT_GT(Images().size(), 1000u);
  EXPECT_GT(same / n, 0.97);
  EXPECT_GT(same_count / n, 0.99);
  EXPECT_LT(worst, 5.0);  // half a bin
}

// Descriptor differences to OpenCV over all comparison images, for the same
// orientations.
void CompareWithOpenCv(const SiftDescriptorOptions& options) {
  DepthSiftDescriber describer(options);
  double bin_sum = 0, distance_sum = 0, worst_distance = 0;
  int worst_bin = 0, identical = 0, descriptors = 0, unrelated_pairs = 0;
  double unrelated = 0;
  std::vector<uint8_t> previous;
  std::chrono::duration<double, std::micro> our_time{0}, their_time{0};
  for (const DepthImage& image : Images()) {
    std::vector<float> thetas{0.0f};
    if (options.orientation == ImageOrientation::kDominant) {
      thetas = DominantOrientations(image);
      if (thetas.empty()) thetas = {0.0f};
    }
    std::vector<uint8_t> ours, theirs;
    const auto start = std::chrono::steady_clock::now();
    ASSERT_EQ(describer.Describe(image, &ours), static_cast<int>(thetas.size()));
    const auto middle = std::chrono::steady_clock::now();
    ASSERT_EQ(OpenCvReference(image, options, thetas, &theirs), static_cast<int>(thetas.size()));
    our_time += middle - start;
    their_time += std::chrono::steady_clock::now() - middle;
    for (std::size_t d = 0; d < thetas.size(); ++d) {
      const uint8_t* a = &ours[d * kSiftDimension];
      const uint8_t* b = &theirs[d * kSiftDimension];
      const double distance = DescriptorDistance(a, b);
      distance_sum += distance;
      worst_distance = std::max(worst_distance, distance);
      identical += distance == 0;
      for (int k = 0; k < kSiftDimension; ++k) {
        const int diff = std::abs(a[k] - b[k]);
        bin_sum += diff;
        worst_bin = std::max(worst_bin, diff);
      }
      ++descriptors;
    }
    if (!previous.empty()) {
      unrelated += DescriptorDistance(previous.data(), ours.data());
      ++unrelated_pairs;
    }
    previous.assign(ours.begin(), ours.begin() + kSiftDimension);
  }
  std::cout << descriptors << " descriptors: identical " << double(identical) / descriptors
            << ", per-bin difference mean " << bin_sum / (descriptors * double{kSiftDimension})
            << " max " << worst_bin << ", distance mean " << distance_sum / descriptors << " max "
            << worst_distance << " (unrelated descriptors: " << unrelated / unrelated_pairs
            << "); per image " << our_time.count() / Images().size() << " us, OpenCV "
            << their_time.count() / Images().size() << " us\n";
  EXPECT_LT(distance_sum / descriptors, 2.0);
  EXPECT_LT(worst_distance, 40.0);
  EXPECT_GT(double(identical) / descriptors, 0.5);
}

TEST(SiftDescriptorTest, MatchesOpenCvWithDominantOrientations) {
  CompareWithOpenCv(SiftDescriptorOptions());
}

TEST(SiftDescriptorTest, MatchesOpenCvWithTheUpAxis) {
  CompareWithOpenCv(UpAxisOptions());
}

TEST(SiftDescriptorTest, MatchesOpenCvWithOtherSettings) {
  SiftDescriptorOptions options;
  options.depth_to_gray = DepthToGray::kStretch;
  options.blur_sigma = 0.8;
  CompareWithOpenCv(options);
}

TEST(SiftDescriptorTest, MatchesOpenCvAtOtherImageSizes) {
  // Other window radii and blur borders. (cv::SIFT corrupts its heap on a 3 x
  // 3 image: that size is only checked to be described, below.)
  for (const int size : {9, 41, 61}) {
    for (uint32_t seed = 0; seed < 5; ++seed) {
      const DepthImage image = RandomSmoothImage(size, seed);
      std::vector<float> thetas = DominantOrientations(image);
      if (thetas.empty()) thetas = {0.0f};
      std::vector<uint8_t> ours, theirs;
      DepthSiftDescriber describer{SiftDescriptorOptions()};
      ASSERT_EQ(describer.Describe(image, &ours), static_cast<int>(thetas.size()));
      ASSERT_EQ(OpenCvReference(image, SiftDescriptorOptions(), thetas, &theirs),
                static_cast<int>(thetas.size()));
      for (std::size_t d = 0; d < thetas.size(); ++d) {
        EXPECT_LT(DescriptorDistance(&ours[d * kSiftDimension], &theirs[d * kSiftDimension]), 4.0)
            << "size " << size << " seed " << seed;
      }
    }
  }
  // The blur's border reflects several times over.
  DepthSiftDescriber describer{SiftDescriptorOptions()};
  std::vector<uint8_t> out;
  EXPECT_GE(describer.Describe(RandomSmoothImage(3, 1), &out), 1);
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
