#include "common/global/lfd.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "common/geometry/test_meshes.h"
#include "common/render/view_renderer.h"

namespace meshseek {
namespace {

using testing_meshes::Append;
using testing_meshes::AxisAngle;

TriangleMesh Box(double sx, double sy, double sz, Vec3d at = {0, 0, 0}) {
  TriangleMesh m = testing_meshes::Cube(0.5f);
  for (Vec3f& v : m.vertices) {
    v = Vec3f(static_cast<float>(v.x * sx + at.x),
              static_cast<float>(v.y * sy + at.y),
              static_cast<float>(v.z * sz + at.z));
  }
  return m;
}

TriangleMesh Sphere(double r, Vec3d at = {0, 0, 0}) {
  TriangleMesh m = testing_meshes::Icosphere(3, static_cast<float>(r));
  for (Vec3f& v : m.vertices) v += Vec3f(at);
  return m;
}

// Test shapes, several of them overlapping multi-component models.
struct NamedShape {
  std::string name;
  TriangleMesh mesh;
};
std::vector<NamedShape> Shapes() {
  std::vector<NamedShape> shapes;
  shapes.push_back({"cube", Box(1, 1, 1)});
  shapes.push_back({"plank", Box(4, 1, 0.3)});
  shapes.push_back({"sphere", Sphere(1)});
  TriangleMesh dumbbell = Sphere(0.6, {-1.5, 0, 0});
  Append(Sphere(0.6, {1.5, 0, 0}), &dumbbell);
  Append(Box(3, 0.25, 0.25), &dumbbell);
  shapes.push_back({"dumbbell", dumbbell});
  TriangleMesh ell = Box(3, 0.6, 0.6, {0, 0, 0});
  Append(Box(0.6, 2, 0.6, {-1.2, 1, 0}), &ell);
  shapes.push_back({"L", ell});
  TriangleMesh cross = Box(3, 0.5, 0.5);
  Append(Box(0.5, 3, 0.5), &cross);
  Append(Box(0.5, 0.5, 3), &cross);
  shapes.push_back({"jack", cross});
  return shapes;
}

// A uniform random rotation (from a fixed-seed generator).
std::array<double, 9> RandomRotation(std::mt19937* rng) {
  std::normal_distribution<double> normal;
  const Vec3d axis = Normalized(Vec3d(normal(*rng), normal(*rng), normal(*rng)));
  std::uniform_real_distribution<double> angle(0, 3.14159265358979323846);
  return AxisAngle(axis, angle(*rng));
}

std::vector<uint8_t> Extract(const TriangleMesh& mesh) {
  auto d = ExtractLfd(mesh, LfdOptions());
  EXPECT_TRUE(d.ok()) << d.status();
  return d.ok() ? *d : std::vector<uint8_t>(kLfdDescriptorBytes, 0);
}

TEST(LfdOptionsTest, DefaultsArePinnedAndValid) {
  const LfdOptions options;
  EXPECT_EQ(options.image_size, 128);
  EXPECT_EQ(options.contour_samples, 128);
  EXPECT_EQ(options.zernike_radius, LfdZernikeRadius::kPerView);
  EXPECT_TRUE(options.Validate().ok());
  LfdOptions bad;
  bad.image_size = 16;
  EXPECT_EQ(bad.Validate().code(), absl::StatusCode::kInvalidArgument);
  bad = LfdOptions();
  bad.contour_samples = 4;
  EXPECT_EQ(bad.Validate().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(kLfdDescriptorBytes, 4800u);
}

TEST(LfdQuantizeTest, FloorsClampsAndMapsNanToZero) {
  EXPECT_EQ(QuantizeLfdCoefficient(0.5, 256), 128);
  EXPECT_EQ(QuantizeLfdCoefficient(0.999, 256), 255);
  EXPECT_EQ(QuantizeLfdCoefficient(3.0, 512), 255);
  EXPECT_EQ(QuantizeLfdCoefficient(-1.0, 256), 0);
  EXPECT_EQ(QuantizeLfdCoefficient(std::nan(""), 256), 0);
}

TEST(ExtractLfdTest, InvalidMeshesAreRejectedWithTheProblemNamed) {
  auto none = ExtractLfd(TriangleMesh(), LfdOptions());
  EXPECT_EQ(none.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(std::string(none.status().message()).find("no faces"), std::string::npos)
      << none.status();
  TriangleMesh point;
  point.vertices = {Vec3f(1, 2, 3), Vec3f(1, 2, 3), Vec3f(1, 2, 3)};
  point.triangles = {{0, 1, 2}};
  auto collapsed = ExtractLfd(point, LfdOptions());
  EXPECT_EQ(collapsed.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(std::string(collapsed.status().message()).find("lfd: "), std::string::npos);
  LfdOptions bad;
  bad.image_size = 0;
  EXPECT_EQ(ExtractLfd(Box(1, 1, 1), bad).status().code(), absl::StatusCode::kInvalidArgument);
}

TEST(ExtractLfdTest, FixedSizeZeroPaddingAndDeterministic) {
  const TriangleMesh mesh = Shapes()[3].mesh;
  const std::vector<uint8_t> a = Extract(mesh), b = Extract(mesh);
  EXPECT_EQ(a.size(), kLfdDescriptorBytes);
  EXPECT_TRUE(ValidateLfdDescriptor(a).ok());
  EXPECT_EQ(a, b);
  EXPECT_EQ(ValidateLfdDescriptor(std::vector<uint8_t>(10)).code(),
            absl::StatusCode::kInvalidArgument);
  std::vector<uint8_t> padded = a;
  padded[kLfdCoefficientsPerView] = 1;
  EXPECT_EQ(ValidateLfdDescriptor(padded).code(), absl::StatusCode::kInvalidArgument);
}

// A flat square: the cameras in its plane (light field 0 has three) see an
// empty silhouette; the descriptor is still finite and compares normally.
TEST(ExtractLfdTest, EmptySilhouettesGiveZerosNotNan) {
  const TriangleMesh plane = testing_meshes::Plane(2);
  const std::vector<uint8_t> d = Extract(plane);
  int empty_views = 0;
  for (int v = 0; v < kLfdViews; ++v) {
    const uint8_t* block = d.data() + v * kLfdViewStride;
    if (std::all_of(block, block + kLfdCoefficientsPerView, [](uint8_t b) { return b == 0; }))
      ++empty_views;
  }
  EXPECT_GE(empty_views, 1);
  EXPECT_EQ(LfdDistance(d.data(), d.data()), 0.0f);
  const std::vector<uint8_t> cube = Extract(Box(1, 1, 1));
  const float to_cube = LfdDistance(d.data(), cube.data());
  EXPECT_TRUE(std::isfinite(to_cube));
  EXPECT_GT(to_cube, 0.0f);
}

TEST(LfdDistanceTest, ScalarAndAvx2PathsAgreeBitForBit) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> byte(0, 255);
  std::vector<std::vector<uint8_t>> descriptors;
  for (int k = 0; k < 4; ++k) {
    std::vector<uint8_t> d(kLfdDescriptorBytes, 0);
    for (int v = 0; v < kLfdViews; ++v) {
      for (int c = 0; c < kLfdCoefficientsPerView; ++c)
        d[v * kLfdViewStride + c] = static_cast<uint8_t>(byte(rng));
    }
    descriptors.push_back(d);
  }
  descriptors.push_back(Extract(Box(1, 1, 1)));
  descriptors.push_back(Extract(Sphere(1)));
  // Nothing alike: 10 views x 45 x 255 = 114,750, past the vector kernel's
  // 16-bit sums, so the exact fallback decides.
  std::vector<uint8_t> full(kLfdDescriptorBytes, 0), empty(kLfdDescriptorBytes, 0);
  for (int v = 0; v < kLfdViews; ++v)
    std::fill_n(full.begin() + v * kLfdViewStride, kLfdCoefficientsPerView, 255);
  EXPECT_EQ(internal::LfdDistanceAtLevel(full.data(), empty.data(), SimdLevel::kAvx2), 114750.0f);
  EXPECT_EQ(internal::LfdDistanceAtLevel(full.data(), empty.data(), SimdLevel::kSse2), 114750.0f);
  descriptors.push_back(full);
  descriptors.push_back(empty);
  for (const auto& a : descriptors) {
    for (const auto& b : descriptors) {
      EXPECT_EQ(internal::LfdDistanceAtLevel(a.data(), b.data(), SimdLevel::kSse2),
                internal::LfdDistanceAtLevel(a.data(), b.data(), SimdLevel::kAvx2));
    }
  }
}

// The brute-force definition: min over light-field pairs and the 60
// rotations of the summed view L1 distances.
TEST(LfdDistanceTest, MatchesTheDefinition) {
  const std::vector<uint8_t> a = Extract(Shapes()[4].mesh), b = Extract(Shapes()[5].mesh);
  int best = 1 << 30;
  for (int la = 0; la < kLfdLightFields; ++la) {
    for (int lb = 0; lb < kLfdLightFields; ++lb) {
      for (const ViewPermutation& p : ViewPermutations()) {
        int sum = 0;
        for (int i = 0; i < kLfdViewsPerLightField; ++i) {
          const uint8_t* va = a.data() + (la * 10 + i) * kLfdViewStride;
          const uint8_t* vb = b.data() + (lb * 10 + p[i]) * kLfdViewStride;
          for (int c = 0; c < kLfdCoefficientsPerView; ++c) sum += std::abs(va[c] - vb[c]);
        }
        best = std::min(best, sum);
      }
    }
  }
  EXPECT_EQ(LfdDistance(a.data(), b.data()), static_cast<float>(best));
}

// The invariances, with their tolerance stated relative to how far apart
// different shapes are: a rotated (uniformly random), scaled and moved copy
// of a shape must be nearer to it than a third of its distance to the
// nearest different shape. Measured (defaults): sphere 0, plank 0.05,
// cube 0.10, dumbbell 0.10, jack 0.15, L 0.18 of that distance. Soups and
// welded meshes render alike, so they are at distance 0.
TEST(LfdDistanceTest, ZeroToItselfSymmetricAndNearlyInvariantToSimilarities) {
  const std::vector<NamedShape> shapes = Shapes();
  std::vector<std::vector<uint8_t>> d;
  for (const NamedShape& s : shapes) d.push_back(Extract(s.mesh));
  std::mt19937 rng(2024);
  for (std::size_t i = 0; i < shapes.size(); ++i) {
    EXPECT_EQ(LfdDistance(d[i].data(), d[i].data()), 0.0f);
    float nearest_other = 1e30f;
    for (std::size_t j = 0; j < shapes.size(); ++j) {
      if (j == i) continue;
      const float dij = LfdDistance(d[i].data(), d[j].data());
      EXPECT_EQ(dij, LfdDistance(d[j].data(), d[i].data()));
      nearest_other = std::min(nearest_other, dij);
    }
    TriangleMesh moved = shapes[i].mesh;
    TransformMesh(RandomRotation(&rng), 3.7, Vec3d(5, -2, 11), &moved);
    const std::vector<uint8_t> dm = Extract(moved);
    const float to_moved = LfdDistance(d[i].data(), dm.data());
    EXPECT_LT(to_moved, nearest_other / 3) << shapes[i].name << ": to its moved copy " << to_moved
                                           << ", to the nearest other shape " << nearest_other;
    EXPECT_EQ(LfdDistance(d[i].data(), Extract(testing_meshes::ToSoup(shapes[i].mesh)).data()),
              0.0f)
        << shapes[i].name;
  }
}

// The original's shared radius is one option away and behaves the same way.
TEST(ExtractLfdTest, SharedLightFieldRadiusAlsoWorks) {
  LfdOptions shared;
  shared.zernike_radius = LfdZernikeRadius::kPerLightField;
  const TriangleMesh mesh = Shapes()[4].mesh;
  auto a = ExtractLfd(mesh, shared);
  ASSERT_TRUE(a.ok()) << a.status();
  EXPECT_TRUE(ValidateLfdDescriptor(*a).ok());
  EXPECT_EQ(LfdDistance(a->data(), a->data()), 0.0f);
  EXPECT_NE(*a, Extract(mesh));
  LfdOptions bad;
  bad.zernike_radius = static_cast<LfdZernikeRadius>(7);
  EXPECT_EQ(bad.Validate().code(), absl::StatusCode::kInvalidArgument);
}

TEST(LfdDistanceMatrixTest, MatchesPairwiseDistancesOnAnyThreadCount) {
  std::vector<std::vector<uint8_t>> d;
  for (const NamedShape& s : Shapes()) d.push_back(Extract(s.mesh));
  auto one = LfdDistanceMatrix(d, 1);
  auto two = LfdDistanceMatrix(d, 2);
  ASSERT_TRUE(one.ok() && two.ok());
  EXPECT_EQ(*one, *two);
  const std::size_t n = d.size();
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = 0; j < n; ++j) {
      EXPECT_EQ((*one)[i * n + j], i == j ? 0.0f : LfdDistance(d[i].data(), d[j].data()));
    }
  }
  d[2].pop_back();
  auto bad = LfdDistanceMatrix(d, 1);
  EXPECT_EQ(bad.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(std::string(bad.status().message()).find("model 2"), std::string::npos);
}


// A rendered view described alone is the block ExtractLfd wrote for it: one
// way to describe a silhouette, for models and pictures alike.
TEST(DescribeLfdSilhouetteTest, ARenderedViewGivesExtractLfdsBlockAndDistanceZero) {
  const LfdOptions options;
  const TriangleMesh mesh = Shapes()[4].mesh;  // the L
  const absl::StatusOr<std::vector<uint8_t>> descriptor = ExtractLfd(mesh, options);
  ASSERT_TRUE(descriptor.ok()) << descriptor.status();
  ViewRenderOptions render_options;
  render_options.image_size = options.image_size;
  absl::StatusOr<ViewRenderer> renderer = ViewRenderer::Create(mesh, render_options);
  ASSERT_TRUE(renderer.ok()) << renderer.status();
  for (const auto& [l, v] : {std::pair{0, 0}, std::pair{3, 7}, std::pair{9, 9}}) {
    const std::vector<uint8_t> mask =
        renderer->Render(Rotate(LightFieldRotations()[l], LightFieldViewDirections()[v])).mask;
    const auto block = DescribeLfdSilhouette({mask.data(), options.image_size, options.image_size},
                                             options);
    ASSERT_TRUE(block.ok()) << block.status();
    const uint8_t* written = descriptor->data() + (l * kLfdViewsPerLightField + v) * kLfdViewStride;
    EXPECT_TRUE(std::equal(block->begin(), block->end(), written)) << "view " << l << "," << v;
    EXPECT_EQ(LfdViewDistance(block->data(), descriptor->data()), 0);
  }
}

TEST(DescribeLfdSilhouetteTest, ViewDistanceIsTheNearestViewsL1AndMirrorsMatch) {
  const LfdOptions options;
  const std::vector<NamedShape> shapes = Shapes();
  const std::vector<uint8_t> plank = *ExtractLfd(shapes[1].mesh, options);
  // An asymmetric silhouette (an L of pixels) and its mirror image.
  const int n = options.image_size;
  std::vector<uint8_t> ell(static_cast<std::size_t>(n) * n, 0), mirror = ell;
  for (int y = 20; y < 100; ++y) {
    for (int x = 30; x < 90; ++x) {
      if (x < 50 || y > 80) ell[y * n + x] = mirror[y * n + (n - 1 - x)] = 1;
    }
  }
  const auto a = DescribeLfdSilhouette({ell.data(), n, n}, options);
  const auto b = DescribeLfdSilhouette({mirror.data(), n, n}, options);
  ASSERT_TRUE(a.ok() && b.ok());
  int mirror_l1 = 0;
  for (int k = 0; k < kLfdCoefficientsPerView; ++k) mirror_l1 += std::abs((*a)[k] - (*b)[k]);
  EXPECT_LE(mirror_l1, 2);  // the same up to rounding at a quantisation step
  float best = 1e9f;
  for (int v = 0; v < kLfdViews; ++v) {
    float sum = 0;
    for (int k = 0; k < kLfdCoefficientsPerView; ++k) {
      sum += std::abs((*a)[k] - plank[v * kLfdViewStride + k]);
    }
    best = std::min(best, sum);
  }
  EXPECT_EQ(LfdViewDistance(a->data(), plank.data()), best);
  EXPECT_GT(best, 0);
  // Empty images are refused; an empty silhouette describes as zeros.
  EXPECT_FALSE(DescribeLfdSilhouette({nullptr, 0, 0}, options).ok());
  const std::vector<uint8_t> blank(static_cast<std::size_t>(n) * n, 0);
  const auto zeros = DescribeLfdSilhouette({blank.data(), n, n}, options);
  ASSERT_TRUE(zeros.ok());
  EXPECT_TRUE(std::all_of(zeros->begin(), zeros->end(), [](uint8_t b) { return b == 0; }));
}

}  // namespace
}  // namespace meshseek
