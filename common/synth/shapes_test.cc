#include "common/synth/shapes.h"

#include <gtest/gtest.h>

#include <cmath>

#include "common/synth/test_checks.h"

namespace meshseek {
namespace {

using synth_testing::EulerCharacteristic;
using synth_testing::OrientationErrors;
using synth_testing::SignedVolume;

constexpr double kPi = 3.14159265358979323846;

void ExpectClosedSurface(const TriangleMesh& mesh, long euler = 2) {
  ASSERT_TRUE(ValidateMesh(mesh).ok()) << ValidateMesh(mesh);
  const MeshTopologyStats stats = ComputeTopologyStats(mesh);
  EXPECT_EQ(stats.components, 1u);
  EXPECT_EQ(stats.boundary_edges, 0u);
  EXPECT_EQ(stats.non_manifold_edges, 0u);
  EXPECT_EQ(stats.unreferenced_vertices, 0u);
  EXPECT_EQ(OrientationErrors(mesh, /*closed=*/true), 0);
  EXPECT_EQ(EulerCharacteristic(mesh), euler);
  EXPECT_GT(SignedVolume(mesh), 0);  // outward normals
}

TEST(ShapesTest, EllipsoidIsClosedWithDocumentedLayout) {
  VertexGrid grid;
  const TriangleMesh e = MakeEllipsoid({1, 2, 3}, 24, 48, &grid);
  ExpectClosedSurface(e);
  EXPECT_EQ(e.vertices.size(), 2u + 23u * 48u);
  EXPECT_EQ(e.vertices.front(), Vec3f(0, 0, 3));
  EXPECT_EQ(e.vertices.back(), Vec3f(0, 0, -3));
  EXPECT_EQ(grid.num_rows(), 23);
  EXPECT_EQ(grid.num_cols(), 48);
  EXPECT_TRUE(grid.wrap_cols);
  EXPECT_NEAR(SignedVolume(e), 4.0 / 3 * kPi * 6, 0.03 * 4.0 / 3 * kPi * 6);
  // Clamped to the minimum: an octahedron-like 2 x 3 ellipsoid.
  ExpectClosedSurface(MakeEllipsoid({1, 1, 1}, 0, 0));
}

TEST(ShapesTest, BoxIsClosedAndWelded) {
  std::array<VertexGrid, 6> faces;
  const TriangleMesh box = MakeBox({2, 1, 0.5}, 0.5, &faces);
  ExpectClosedSurface(box);
  EXPECT_NEAR(SignedVolume(box), 1.0, 1e-9);
  // Lattice 4 x 2 x 1: surface points = all (5*3*2 = 30) minus interior (none).
  EXPECT_EQ(box.vertices.size(), 30u);
  EXPECT_EQ(faces[5].num_rows(), 5);  // -z face: rows along x (4 quads), columns along y
  EXPECT_EQ(faces[5].num_cols(), 3);
  for (uint32_t v : faces[5].rows[1]) EXPECT_FLOAT_EQ(box.vertices[v].z, -0.25f);
}

TEST(ShapesTest, TorusIsClosedWithGenusOne) {
  const TriangleMesh torus = MakeTorus(1.0, 0.25, 64, 24);
  ExpectClosedSurface(torus, /*euler=*/0);
  const double volume = 2 * kPi * kPi * 1.0 * 0.25 * 0.25;
  EXPECT_NEAR(SignedVolume(torus), volume, 0.02 * volume);
}

TEST(ShapesTest, SurfaceOfRevolutionIsOpenWhereTheProfileIs) {
  VertexGrid grid;
  auto vase = MakeSurfaceOfRevolution({{0, 0}, {1, 0}, {1.2, 1}, {0.5, 2}}, 16, &grid);
  ASSERT_TRUE(vase.ok()) << vase.status();
  EXPECT_TRUE(ValidateMesh(*vase).ok());
  const MeshTopologyStats stats = ComputeTopologyStats(*vase);
  EXPECT_EQ(stats.components, 1u);
  EXPECT_EQ(stats.boundary_edges, 16u);  // the open mouth
  EXPECT_EQ(stats.non_manifold_edges, 0u);
  EXPECT_EQ(OrientationErrors(*vase, /*closed=*/false), 0);
  EXPECT_EQ(grid.num_rows(), 3);

  auto closed = MakeSurfaceOfRevolution({{0, -1}, {1, 0}, {0, 1}}, 12);
  ASSERT_TRUE(closed.ok());
  ExpectClosedSurface(*closed);

  EXPECT_FALSE(MakeSurfaceOfRevolution({{1, 0}}, 8).ok());
  EXPECT_FALSE(MakeSurfaceOfRevolution({{1, 0}, {0, 1}, {1, 2}}, 8).ok());  // pinched
  EXPECT_FALSE(MakeSurfaceOfRevolution({{0, 0}, {0, 1}}, 8).ok());
  EXPECT_FALSE(MakeSurfaceOfRevolution({{1, 0}, {-1, 1}}, 8).ok());
}

TEST(ShapesTest, TubeIsAClosedPrismWithFlatCaps) {
  TubeOptions options;
  options.sides = 6;
  options.cap_height = 0;
  VertexGrid grid;
  auto tube = MakeTube(
      {{0, 0, 0}, {0, 0, 1}, {0, 0, 2}}, [](double) { return 0.5; }, options, &grid);
  ASSERT_TRUE(tube.ok()) << tube.status();
  ExpectClosedSurface(*tube);
  // A hexagonal prism: area of the hexagon inscribed in r = 0.5, times 2.
  EXPECT_NEAR(SignedVolume(*tube), 2 * 1.5 * std::sqrt(3.0) * 0.25, 1e-5);
  EXPECT_EQ(grid.num_rows(), 3);
  EXPECT_EQ(grid.num_cols(), 6);

  options.cap_start = options.cap_end = false;
  auto open = MakeTube(
      {{0, 0, 0}, {1, 1, 0}}, [](double t) { return 1 - 0.5 * t; }, options);
  ASSERT_TRUE(open.ok());
  EXPECT_EQ(ComputeTopologyStats(*open).boundary_edges, 12u);

  EXPECT_FALSE(MakeTube(
                   {{0, 0, 0}}, [](double) { return 1.0; }, options)
                   .ok());
  EXPECT_FALSE(MakeTube(
                   {{0, 0, 0}, {0, 0, 0}}, [](double) { return 1.0; }, options)
                   .ok());
  EXPECT_FALSE(MakeTube(
                   {{0, 0, 0}, {1, 0, 0}}, [](double) { return 0.0; }, options)
                   .ok());
}

TEST(ShapesTest, TubeFollowsABentPathWithoutTwisting) {
  std::vector<Vec3d> path;
  for (int i = 0; i <= 40; ++i) {
    const double a = kPi * i / 40;
    path.push_back({std::cos(a), std::sin(a), 0.3 * a});
  }
  TubeOptions options;
  options.sides = 8;
  VertexGrid grid;
  auto tube = MakeTube(
      path, [](double) { return 0.1; }, options, &grid);
  ASSERT_TRUE(tube.ok());
  ExpectClosedSurface(*tube);
  // Column 0 of neighbouring rings stays close: no twist between rings.
  for (int r = 1; r < grid.num_rows(); ++r) {
    EXPECT_LT(Distance(tube->vertices[grid.rows[r][0]], tube->vertices[grid.rows[r - 1][0]]),
              0.15f);
  }
}

TEST(ShapesTest, VertexGridPatchWrapsAndChecksBounds) {
  VertexGrid grid;
  MakeEllipsoid({1, 1, 1}, 6, 8, &grid);
  const std::vector<uint32_t> patch = grid.Patch(1, 7, 2, 2);  // columns 7, 0, 1
  ASSERT_EQ(patch.size(), 9u);
  EXPECT_EQ(patch[1], grid.rows[1][0]);
  EXPECT_TRUE(grid.Patch(4, 0, 1, 1).empty());  // rows 4..5 of 0..4
  EXPECT_TRUE(grid.Patch(0, 0, 1, 8).empty());  // would wrap onto itself
  EXPECT_TRUE(grid.Patch(0, 0, 0, 1).empty());
  grid.wrap_cols = false;
  EXPECT_TRUE(grid.Patch(1, 7, 1, 1).empty());
}

TEST(ShapesTest, CutHoleReturnsTheOrientedRimOfADisk) {
  VertexGrid grid;
  TriangleMesh mesh = MakeEllipsoid({1, 1, 1}, 12, 16, &grid);
  const std::size_t triangles = mesh.triangles.size();
  auto rim = CutHole(grid.Patch(4, 3, 2, 3), &mesh);
  ASSERT_TRUE(rim.ok()) << rim.status();
  EXPECT_EQ(rim->size(), 10u);  // 2 (2 + 3)
  EXPECT_EQ(mesh.triangles.size(), triangles - 12);
  EXPECT_EQ(ComputeTopologyStats(mesh).boundary_edges, 10u);
  // The rim runs as the removed triangles did, i.e. against the remaining ones.
  EXPECT_EQ(OrientationErrors(mesh, /*closed=*/false), 0);
  for (std::size_t m = 0; m < rim->size(); ++m) {
    const uint32_t a = (*rim)[m], b = (*rim)[(m + 1) % rim->size()];
    bool reverse_used = false;
    for (const Triangle& t : mesh.triangles) {
      for (int k = 0; k < 3; ++k) reverse_used |= t[k] == b && t[(k + 1) % 3] == a;
    }
    EXPECT_TRUE(reverse_used) << "rim edge " << a << " -> " << b;
  }
}

TEST(ShapesTest, CutHoleRejectsWhatIsNotADiskAndLeavesTheMesh) {
  VertexGrid grid;
  TriangleMesh mesh = MakeEllipsoid({1, 1, 1}, 12, 16, &grid);
  const std::size_t triangles = mesh.triangles.size();
  EXPECT_FALSE(CutHole({}, &mesh).ok());
  EXPECT_FALSE(CutHole({grid.rows[2][2], grid.rows[5][5]}, &mesh).ok());  // no triangle
  std::vector<uint32_t> two = grid.Patch(2, 0, 1, 1);
  const std::vector<uint32_t> other = grid.Patch(6, 8, 1, 1);
  two.insert(two.end(), other.begin(), other.end());
  EXPECT_FALSE(CutHole(two, &mesh).ok());     // two disks: two rims
  std::vector<uint32_t> band = grid.rows[3];  // a closed band of rows 3-4: an annulus
  band.insert(band.end(), grid.rows[4].begin(), grid.rows[4].end());
  EXPECT_FALSE(CutHole(band, &mesh).ok());
  EXPECT_EQ(mesh.triangles.size(), triangles);
  EXPECT_FALSE(CutHole({static_cast<uint32_t>(mesh.vertices.size())}, &mesh).ok());
}

TEST(ShapesTest, ExtrudedLimbKeepsTheSurfaceClosed) {
  VertexGrid grid;
  TriangleMesh mesh = MakeEllipsoid({1, 1, 1}, 12, 16, &grid);
  const double volume = SignedVolume(mesh);
  auto rim = CutHole(grid.Patch(5, 0, 1, 2), &mesh);  // at the equator, +x side
  ASSERT_TRUE(rim.ok());
  TubeOptions options;
  options.sides = 7;  // not the rim's 6: rings are stitched by angle
  auto limb = ExtrudeTube(
      *rim,
      {{1.2, 0.1, 0}, {1.6, 0.1, 0.2}, {2.0, 0.1, 0.5}},
      [](double t) { return 0.2 * (1 - 0.5 * t); },
      options,
      &mesh);
  ASSERT_TRUE(limb.ok()) << limb.status();
  EXPECT_EQ(limb->num_rows(), 3);
  EXPECT_EQ(limb->num_cols(), 7);
  RemoveUnreferencedVertices(&mesh);
  ExpectClosedSurface(mesh);
  EXPECT_GT(SignedVolume(mesh), volume);  // the limb adds to the volume
  EXPECT_FALSE(ExtrudeTube(
                   {0, 1}, {{0, 0, 2}}, [](double) { return 1.0; }, options, &mesh)
                   .ok());
}

TEST(ShapesTest, SquareHoleGivesASquareLeg) {
  std::array<VertexGrid, 6> faces;
  TriangleMesh mesh = MakeBox({1, 1, 0.2}, 0.1, &faces);
  auto rim = CutHole(faces[5].Patch(1, 1, 2, 2), &mesh);  // near a corner of -z
  ASSERT_TRUE(rim.ok());
  TubeOptions options;
  options.keep_rim_shape = true;
  options.cap_height = 0;
  const Vec3d c = (Vec3d(mesh.vertices[(*rim)[0]]) + Vec3d(mesh.vertices[(*rim)[4]])) * 0.5;
  auto leg = ExtrudeTube(
      *rim, {c - Vec3d(0, 0, 0.5), c - Vec3d(0, 0, 1)}, [](double) { return 0.1; }, options, &mesh);
  ASSERT_TRUE(leg.ok()) << leg.status();
  EXPECT_EQ(leg->num_cols(), 8);  // the rim's vertex count
  RemoveUnreferencedVertices(&mesh);
  ExpectClosedSurface(mesh);
  // The foot is a square ring under the hole at z = -1.1.
  for (uint32_t v : leg->rows.back()) {
    EXPECT_NEAR(mesh.vertices[v].z, -1.1, 1e-5);
    EXPECT_LE(std::abs(mesh.vertices[v].x - c.x), 0.1 * std::sqrt(2.0) + 1e-5);
  }
}

TEST(ShapesTest, BridgeJoinsTwoBodiesIntoOne) {
  TriangleMesh mesh;
  VertexGrid a, b;
  AppendMesh(MakeEllipsoid({1, 1, 1}, 12, 16, &a), &mesh);
  TriangleMesh right = MakeEllipsoid({1, 1, 1}, 12, 16, &b);
  TransformMesh({-1, 0, 0, 0, -1, 0, 0, 0, 1}, 1.0, {4, 0, 0}, &right);  // faces -x
  b.Shift(AppendMesh(right, &mesh));
  auto rim_a = CutHole(a.Patch(5, 15, 1, 2), &mesh);
  auto rim_b = CutHole(b.Patch(5, 15, 1, 2), &mesh);
  ASSERT_TRUE(rim_a.ok() && rim_b.ok());
  ASSERT_TRUE(BridgeHoles(
                  *rim_a,
                  *rim_b,
                  {{1.5, 0, 0}, {2, 0, 0.3}, {2.5, 0, 0}},
                  [](double) { return 0.2; },
                  9,
                  &mesh)
                  .ok());
  RemoveUnreferencedVertices(&mesh);
  ExpectClosedSurface(mesh);  // two spheres and a tube: one sphere
  EXPECT_FALSE(BridgeHoles(
                   *rim_a, *rim_b, {}, [](double) { return 0.2; }, 9, &mesh)
                   .ok());
}

TEST(ShapesTest, PolylineSmoothingAndResampling) {
  const std::vector<Vec3d> joints = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}};
  const std::vector<Vec3d> smooth = SmoothPolyline(joints, 2);
  ASSERT_EQ(smooth.size(), 12u);  // 3 -> 6 -> 12 points
  EXPECT_EQ(smooth.front(), joints.front());
  EXPECT_EQ(smooth.back(), joints.back());
  EXPECT_EQ(SmoothPolyline(joints, 0), joints);

  const std::vector<Vec3d> even = ResamplePolyline(joints, 0.25);
  ASSERT_EQ(even.size(), 9u);
  EXPECT_EQ(even.front(), joints.front());
  EXPECT_EQ(even.back(), joints.back());
  for (std::size_t i = 1; i < even.size(); ++i) {
    EXPECT_NEAR(Distance(even[i - 1], even[i]), 0.25, 1e-12);
  }
  EXPECT_EQ(ResamplePolyline(joints, 0).size(), 3u);
}

TEST(ShapesTest, PolygonSoupAndAppend) {
  const TriangleMesh ball = MakeEllipsoid({1, 1, 1}, 6, 8);
  const TriangleMesh soup = MakePolygonSoup(ball);
  EXPECT_EQ(soup.vertices.size(), 3 * ball.triangles.size());
  EXPECT_EQ(ComputeTopologyStats(soup).components, soup.triangles.size());
  EXPECT_NEAR(SurfaceArea(soup), SurfaceArea(ball), 1e-9);

  TriangleMesh two = ball;
  EXPECT_EQ(AppendMesh(ball, &two), ball.vertices.size());
  EXPECT_EQ(ComputeTopologyStats(two).components, 2u);
  two.triangles.resize(ball.triangles.size());
  RemoveUnreferencedVertices(&two);
  EXPECT_EQ(two.vertices.size(), ball.vertices.size());
  EXPECT_TRUE(ValidateMesh(two).ok());
}

}  // namespace
}  // namespace meshseek
