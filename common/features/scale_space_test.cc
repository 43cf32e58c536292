#include "common/features/scale_space.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>

#include "common/geometry/mesh_vertex_graph.h"
#include "common/geometry/test_meshes.h"

namespace meshseek {
namespace {

// A unit sphere with a Gaussian bump of height `height` and width `width`
// (radians) around the north pole.
TriangleMesh BumpySphere(int levels, double height, double width) {
  TriangleMesh mesh = testing_meshes::Icosphere(levels, 1.0f);
  for (Vec3f& v : mesh.vertices) {
    const double angle = std::acos(std::clamp(static_cast<double>(v.z), -1.0, 1.0));
    const double r = 1.0 + height * std::exp(-angle * angle / (2 * width * width));
    v = Vec3f(Vec3d(v) * r);
  }
  return mesh;
}

TEST(ScaleSpaceOptionsTest, DefaultsArePinnedAndValid) {
  const ScaleSpaceOptions options;
  EXPECT_EQ(options.levels, 20);
  EXPECT_EQ(options.scale_factor, 5.0);
  EXPECT_TRUE(options.Validate().ok());
  ScaleSpaceOptions bad;
  bad.levels = 1;
  EXPECT_NE(bad.Validate().message().find("got 1"), absl::string_view::npos);
}

TEST(ScaleSpaceTest, FiresOnABumpAtALevelThatGrowsWithItsSize) {
  const Vec3d pole(0, 0, 1);
  int previous_level = 0;
  for (const double width : {0.08, 0.16, 0.32}) {
    const MeshVertexGraph g = BuildMeshVertexGraph(BumpySphere(5, 0.15, width));
    const auto points = DetectInterestPoints(g.graph, ScaleSpaceOptions());
    ASSERT_FALSE(points.empty());
    // The detected point nearest the bump's apex.
    auto angle_to_pole = [&](const InterestPoint& p) {
      return std::acos(
          std::clamp(Dot(Normalized(Vec3d(g.graph.positions[p.vertex])), pole), -1.0, 1.0));
    };
    const InterestPoint best =
        *std::min_element(points.begin(), points.end(), [&](const auto& a, const auto& b) {
          return angle_to_pole(a) < angle_to_pole(b);
        });
    EXPECT_LT(angle_to_pole(best), 0.25 * width) << "bump width " << width;
    EXPECT_GT(best.level, previous_level) << "bump width " << width;
    EXPECT_NEAR(
        best.scale, 5.0 * g.graph.MeanEdgeLength(best.vertex) * std::sqrt(best.level), 1e-4);
    previous_level = best.level;
  }
}

TEST(ScaleSpaceTest, OutputDoesNotDependOnVertexOrder) {
  const TriangleMesh mesh = BumpySphere(4, 0.2, 0.2);
  const MeshVertexGraph g = BuildMeshVertexGraph(mesh);
  // The same graph with vertices renumbered by a random permutation.
  const std::size_t n = g.graph.size();
  std::vector<uint32_t> perm(n);
  std::iota(perm.begin(), perm.end(), 0u);
  std::shuffle(perm.begin(), perm.end(), std::mt19937(4));
  std::vector<Vec3f> positions(n);
  std::vector<std::pair<uint32_t, uint32_t>> edges;
  for (std::size_t i = 0; i < n; ++i) {
    positions[perm[i]] = g.graph.positions[i];
    for (const uint32_t j : g.graph.NeighborsOf(i)) edges.emplace_back(perm[i], perm[j]);
  }
  const PointGraph permuted = MakePointGraph(positions, edges);
  auto a = DetectInterestPoints(g.graph, ScaleSpaceOptions());
  auto b = DetectInterestPoints(permuted, ScaleSpaceOptions());
  ASSERT_EQ(a.size(), b.size());
  ASSERT_GT(a.size(), 10u);
  for (InterestPoint& p : a) p.vertex = perm[p.vertex];
  auto by_vertex = [](const InterestPoint& x, const InterestPoint& y) {
    return x.vertex < y.vertex;
  };
  std::sort(a.begin(), a.end(), by_vertex);
  for (std::size_t k = 0; k < a.size(); ++k) {
    EXPECT_EQ(a[k].vertex, b[k].vertex);
    EXPECT_EQ(a[k].level, b[k].level);
    EXPECT_NEAR(a[k].scale, b[k].scale, 1e-6f * a[k].scale);
  }
}

TEST(ScaleSpaceTest, SkipsBoundaryVerticesOfOpenMeshes) {
  // A bumpy open square: no interest point may sit on its rim.
  TriangleMesh plane = testing_meshes::Plane(16, 1.0f);
  for (Vec3f& v : plane.vertices) v.z = 0.1f * std::sin(6 * v.x) * std::cos(5 * v.y);
  const MeshVertexGraph g = BuildMeshVertexGraph(plane);
  const auto points = DetectInterestPoints(g.graph, ScaleSpaceOptions());
  ASSERT_FALSE(points.empty());
  for (const InterestPoint& p : points) {
    const Vec3f& v = g.graph.positions[p.vertex];
    EXPECT_LT(std::max(std::abs(v.x), std::abs(v.y)), 0.999f);
    EXPECT_FALSE(g.graph.boundary[p.vertex]);
  }
}

}  // namespace
}  // namespace meshseek
