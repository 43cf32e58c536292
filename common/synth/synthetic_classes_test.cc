#include "common/synth/synthetic_classes.h"

#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <string>

#include "common/synth/test_checks.h"

namespace meshseek {
namespace {

using synth_testing::EulerCharacteristic;
using synth_testing::OrientationErrors;
using synth_testing::SignedVolume;

TEST(SynthRandomTest, UsesTheStandardEngine) {
  // The C++ standard requires the 10000th output of a default-seeded
  // mt19937_64 to be 9981545732273789042.
  SynthRandom rng(5489);
  uint64_t value = 0;
  for (int i = 0; i < 10000; ++i) value = rng.Next();
  EXPECT_EQ(value, 9981545732273789042ULL);
}

TEST(SynthRandomTest, DistributionsHaveTheRightMoments) {
  SynthRandom rng(7);
  constexpr int kN = 200000;
  double sum = 0, sum_sq = 0, normal_sum = 0, normal_sq = 0;
  std::set<int> ints;
  for (int i = 0; i < kN; ++i) {
    const double u = rng.Uniform();
    ASSERT_GE(u, 0.0);
    ASSERT_LT(u, 1.0);
    sum += u;
    sum_sq += u * u;
    const double n = rng.Normal();
    ASSERT_TRUE(std::isfinite(n));
    normal_sum += n;
    normal_sq += n * n;
    const int k = rng.UniformInt(-2, 3);
    ASSERT_GE(k, -2);
    ASSERT_LE(k, 3);
    ints.insert(k);
  }
  EXPECT_NEAR(sum / kN, 0.5, 0.005);
  EXPECT_NEAR(sum_sq / kN - 0.25, 1.0 / 12, 0.003);
  EXPECT_NEAR(normal_sum / kN, 0.0, 0.01);
  EXPECT_NEAR(normal_sq / kN, 1.0, 0.02);
  EXPECT_EQ(ints.size(), 6u);
  EXPECT_EQ(rng.UniformInt(4, 4), 4);
}

TEST(SynthRandomTest, SeedsAreReproducibleAndDistinct) {
  SynthRandom a(42), b(42), c(43);
  for (int i = 0; i < 10; ++i) {
    const double x = a.Uniform();
    EXPECT_EQ(x, b.Uniform());
    EXPECT_NE(x, c.Uniform());
  }
  EXPECT_NE(MixSeed(1, 0), MixSeed(1, 1));
  EXPECT_NE(MixSeed(1, 0), MixSeed(2, 0));
  EXPECT_EQ(MixSeed(1, 2), MixSeed(1, 2));
  EXPECT_EQ(HashName(""), 0xcbf29ce484222325ULL);  // FNV-1a test vectors
  EXPECT_EQ(HashName("a"), 0xaf63dc4c8601ec8cULL);
}

TEST(SyntheticClassesTest, ListsNineNamedClasses) {
  const std::vector<std::string> names = SyntheticClassNames();
  ASSERT_EQ(names.size(), 9u);
  EXPECT_EQ(names.front(), "snake");
  EXPECT_EQ(names.back(), "vase");
  EXPECT_EQ(std::set<std::string>(names.begin(), names.end()).size(), names.size());
  for (const SyntheticClass& c : SyntheticClasses()) {
    EXPECT_GT(std::string(c.description).size(), 10u) << c.name;
    EXPECT_EQ(std::string(c.name).find_first_of(" ,"), std::string::npos);
  }
}

// Welded models are one closed, consistently oriented, manifold surface
// (the vase: one open sheet); unwelded ones have several components. Over
// many seeds and densities, because limbs must always find room on bodies.
TEST(SyntheticClassesTest, EveryClassBuildsValidSurfaces) {
  for (const SyntheticClass& c : SyntheticClasses()) {
    const bool open = std::string(c.name) == "vase";
    for (uint64_t seed = 1; seed <= 12; ++seed) {
      for (const double density : {0.5, 1.0, 3.0}) {
        for (const bool welded : {true, false}) {
          SCOPED_TRACE(testing::Message() << c.name << " seed " << seed << " density " << density
                                          << (welded ? " welded" : " unwelded"));
          SyntheticShapeParams params;
          params.density = density;
          params.welded = welded;
          SynthRandom rng(seed);
          absl::StatusOr<TriangleMesh> mesh = c.build(params, &rng);
          ASSERT_TRUE(mesh.ok()) << mesh.status();
          ASSERT_TRUE(ValidateMesh(*mesh).ok()) << ValidateMesh(*mesh);
          const MeshTopologyStats stats = ComputeTopologyStats(*mesh);
          EXPECT_EQ(stats.unreferenced_vertices, 0u);
          EXPECT_EQ(stats.non_manifold_edges, 0u);
          if (!welded) {
            EXPECT_GT(stats.components, 1u);
            continue;
          }
          EXPECT_EQ(stats.components, 1u);
          EXPECT_EQ(OrientationErrors(*mesh, /*closed=*/!open), 0);
          if (open) {
            EXPECT_GT(stats.boundary_edges, 0u);
            EXPECT_EQ(EulerCharacteristic(*mesh), 1);  // a disk
          } else {
            EXPECT_EQ(stats.boundary_edges, 0u);
            EXPECT_GT(SignedVolume(*mesh), 0);
          }
        }
      }
    }
  }
}

TEST(SyntheticClassesTest, BuildsAreDeterministicAndVary) {
  for (const SyntheticClass& c : SyntheticClasses()) {
    SyntheticShapeParams params;
    SynthRandom a(3), b(3), other(4);
    const absl::StatusOr<TriangleMesh> first = c.build(params, &a);
    const absl::StatusOr<TriangleMesh> again = c.build(params, &b);
    const absl::StatusOr<TriangleMesh> different = c.build(params, &other);
    ASSERT_TRUE(first.ok() && again.ok() && different.ok()) << c.name;
    EXPECT_EQ(first->vertices, again->vertices) << c.name;
    EXPECT_EQ(first->triangles, again->triangles) << c.name;
    EXPECT_NE(first->vertices, different->vertices) << c.name;
  }
}

TEST(SyntheticClassesTest, DensityControlsTheVertexCount) {
  for (const SyntheticClass& c : SyntheticClasses()) {
    SyntheticShapeParams sparse, dense;
    dense.density = 3.0;
    SynthRandom a(5), b(5);
    const absl::StatusOr<TriangleMesh> coarse = c.build(sparse, &a);
    const absl::StatusOr<TriangleMesh> fine = c.build(dense, &b);
    ASSERT_TRUE(coarse.ok() && fine.ok()) << c.name;
    const std::size_t few = coarse->vertices.size(), many = fine->vertices.size();
    EXPECT_GE(few, 150u) << c.name;
    EXPECT_LE(few, 1500u) << c.name;
    EXPECT_GT(many, 3 * few) << c.name;  // about density^2 = 9
    EXPECT_LT(many, 8000u) << c.name;
  }
}

}  // namespace
}  // namespace meshseek
