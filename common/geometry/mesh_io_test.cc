#include "common/geometry/mesh_io.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>

#include "common/geometry/test_meshes.h"

namespace meshseek {
namespace {

using ::testing::HasSubstr;

std::string TempPath(const std::string& name) { return ::testing::TempDir() + "/" + name; }

std::string WriteText(const std::string& name, const std::string& text) {
  const std::string path = TempPath(name);
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

class RoundTripTest : public ::testing::TestWithParam<std::tuple<std::string, bool>> {};

TEST_P(RoundTripTest, EveryFormatReadsBackWhole) {
  const auto& [ext, binary] = GetParam();
  TriangleMesh mesh = testing_meshes::Icosphere(2, 1.5f);
  testing_meshes::Append(testing_meshes::Cube(0.5f), &mesh);  // a second component
  const std::string path =
      TempPath("roundtrip_" + std::string(binary ? "bin" : "ascii") + "." + ext);
  ASSERT_TRUE(WriteMesh(path, mesh, {binary}).ok());
  MeshReadReport report;
  auto read = ReadMesh(path, &report);
  ASSERT_TRUE(read.ok()) << read.status();
  EXPECT_EQ(read->triangles.size(), mesh.triangles.size());
  EXPECT_NEAR(SurfaceArea(*read), SurfaceArea(mesh), 1e-4 * SurfaceArea(mesh));
  EXPECT_EQ(report.topology.components, 2u) << report.Summary();
  EXPECT_EQ(report.faces_dropped, 0u);
  if (ext != "stl") {  // STL has no shared vertices; its reader merges equal ones
    ASSERT_EQ(read->vertices.size(), mesh.vertices.size());
    for (std::size_t v = 0; v < mesh.vertices.size(); ++v) {
      EXPECT_EQ(read->vertices[v], mesh.vertices[v]);
    }
    EXPECT_EQ(read->triangles, mesh.triangles);
  }
}

INSTANTIATE_TEST_SUITE_P(Formats,
                         RoundTripTest,
                         ::testing::Values(std::make_tuple("off", false),
                                           std::make_tuple("off", true),
                                           std::make_tuple("obj", false),
                                           std::make_tuple("ply", false),
                                           std::make_tuple("ply", true),
                                           std::make_tuple("stl", false),
                                           std::make_tuple("stl", true)));

TEST(ReadMeshTest, PolygonSoupIsReadWhole) {
  const TriangleMesh soup = testing_meshes::ToSoup(testing_meshes::Icosphere(2));
  for (const std::string ext : {"off", "ply", "obj"}) {
    const std::string path = TempPath("soup." + ext);
    ASSERT_TRUE(WriteMesh(path, soup).ok());
    MeshReadReport report;
    auto read = ReadMesh(path, &report);
    ASSERT_TRUE(read.ok()) << read.status();
    EXPECT_EQ(read->triangles.size(), soup.triangles.size()) << ext;
    EXPECT_EQ(report.topology.components, soup.triangles.size()) << ext;
    EXPECT_EQ(report.topology.boundary_edges, 3 * soup.triangles.size()) << ext;
  }
}

TEST(ReadMeshTest, KeepsNonManifoldFaces) {
  // Three triangles on one edge (a "book" of three pages) and a bow-tie vertex.
  const std::string path = WriteText("nonmanifold.off",
                                     "OFF\n7 4 0\n0 0 0\n1 0 0\n0 1 0\n0 -1 0\n0 0 1\n"
                                     "-1 -1 -1\n-1 -2 -1\n"
                                     "3 0 1 2\n3 0 1 3\n3 0 1 4\n3 0 5 6\n");
  MeshReadReport report;
  auto read = ReadMesh(path, &report);
  ASSERT_TRUE(read.ok()) << read.status();
  EXPECT_EQ(read->triangles.size(), 4u);
  EXPECT_EQ(report.topology.non_manifold_edges, 1u);
  EXPECT_EQ(report.topology.components, 1u);
}

TEST(ReadMeshTest, TriangulatesPolygonsAndRepairsRepeatedCorners) {
  const std::string path = WriteText("polygons.off",
                                     "OFF\n6 4 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0.5 1.5 0\n0 0 1\n"
                                     "4 0 1 2 3\n"    // quad -> 2 triangles
                                     "5 0 1 2 4 3\n"  // pentagon -> 3 triangles
                                     "4 0 1 1 5\n"    // repeated corner -> 1 triangle
                                     "3 0 0 1\n");    // < 3 distinct corners -> dropped
  MeshReadReport report;
  auto read = ReadMesh(path, &report);
  ASSERT_TRUE(read.ok()) << read.status();
  EXPECT_EQ(report.file_faces, 4u);
  EXPECT_EQ(read->triangles.size(), 6u);
  EXPECT_EQ(report.polygons_triangulated, 2u);
  EXPECT_EQ(report.faces_repaired, 1u);  // the dropped face is not counted as repaired
  EXPECT_EQ(report.faces_dropped, 1u);
  EXPECT_THAT(report.Summary(), HasSubstr("1 faces dropped"));
}

TEST(ReadMeshTest, ObjPolygonsAndNegativeIndices) {
  const std::string path = WriteText("poly.obj",
                                     "# quad and a relative-index triangle\n"
                                     "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\n"
                                     "f 1 2 3 4\nf -5 -4 -1\n");
  MeshReadReport report;
  auto read = ReadMesh(path, &report);
  ASSERT_TRUE(read.ok()) << read.status();
  EXPECT_EQ(read->triangles.size(), 3u);
  EXPECT_EQ(report.polygons_triangulated, 1u);
  EXPECT_EQ(read->triangles[2], (Triangle{0, 1, 4}));
}

// --- Bad input: each kind of bad file is an error naming the file and the problem.

void ExpectError(const std::string& path, absl::StatusCode code, const std::string& what) {
  auto read = ReadMesh(path);
  ASSERT_FALSE(read.ok()) << path;
  EXPECT_EQ(read.status().code(), code) << read.status();
  EXPECT_THAT(std::string(read.status().message()), HasSubstr(path));
  EXPECT_THAT(std::string(read.status().message()), HasSubstr(what));
}

TEST(ReadMeshErrorTest, MissingFile) {
  ExpectError(TempPath("does_not_exist.off"), absl::StatusCode::kNotFound, "cannot open");
}

TEST(ReadMeshErrorTest, UnknownExtension) {
  ExpectError(WriteText("model.xyz", "1 2 3\n"),
              absl::StatusCode::kInvalidArgument,
              "unknown mesh format 'xyz'");
}

TEST(ReadMeshErrorTest, EmptyAndGarbageFiles) {
  ExpectError(WriteText("empty.off", ""), absl::StatusCode::kInvalidArgument, "empty");
  ExpectError(WriteText("garbage.off", "this is not a mesh\n"),
              absl::StatusCode::kInvalidArgument,
              "could not parse the file as OFF");
}

TEST(ReadMeshErrorTest, NonFiniteCoordinatesInAsciiNameTheLine) {
  ExpectError(WriteText("nan.off", "OFF\n3 1 0\n0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n"),
              absl::StatusCode::kInvalidArgument,
              "line 4: non-finite coordinate 'nan'");
  ExpectError(WriteText("inf.obj", "v 0 0 0\nv 1 0 0\nv 0 -inf 0\nf 1 2 3\n"),
              absl::StatusCode::kInvalidArgument,
              "line 3: non-finite coordinate '-inf'");
  ExpectError(
      WriteText("huge.ply",
                "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
                "end_header\n0 0 0\n1e999 0 0\n0 1 0\n3 0 1 2\n"),
      absl::StatusCode::kInvalidArgument,
      "line 11: non-finite coordinate '1e999'");
}

TEST(ReadMeshErrorTest, NonFiniteCoordinatesInBinaryNameTheVertex) {
  TriangleMesh mesh = testing_meshes::Cube();
  mesh.vertices[5].y = std::numeric_limits<float>::quiet_NaN();
  const std::string ply = TempPath("nan_binary.ply");
  ASSERT_TRUE(WriteMesh(ply, mesh, {true}).ok());
  ExpectError(ply, absl::StatusCode::kInvalidArgument, "vertex 5 has a non-finite coordinate");
  mesh.vertices[5].y = std::numeric_limits<float>::infinity();
  const std::string off = TempPath("inf_binary.off");
  ASSERT_TRUE(WriteMesh(off, mesh, {true}).ok());
  ExpectError(off, absl::StatusCode::kInvalidArgument, "vertex 5 has a non-finite coordinate");
}

TEST(ReadMeshErrorTest, IndexOutOfRange) {
  ExpectError(WriteText("range.off", "OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 1 9\n"),
              absl::StatusCode::kInvalidArgument,
              "face 1 (0-based) references vertex 9, but the file has 3 vertices");
  ExpectError(WriteText("range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n"),
              absl::StatusCode::kInvalidArgument,
              "references vertex 3, but the file has 3 vertices");
  TriangleMesh mesh = testing_meshes::Cube();
  mesh.triangles[3][1] = 1000;
  const std::string ply = TempPath("range_binary.ply");
  ASSERT_TRUE(WriteMesh(ply, mesh, {true}).ok());
  ExpectError(ply, absl::StatusCode::kInvalidArgument, "face 3 (0-based) references vertex 1000");
}

TEST(ReadMeshErrorTest, NoFaces) {
  ExpectError(WriteText("nofaces.off", "OFF\n3 0 0\n0 0 0\n1 0 0\n0 1 0\n"),
              absl::StatusCode::kInvalidArgument,
              "mesh has no faces (3 vertices)");
  ExpectError(WriteText("nofaces.obj", "v 0 0 0\nv 1 0 0\n"),
              absl::StatusCode::kInvalidArgument,
              "mesh has no faces");
}

TEST(ReadMeshErrorTest, ZeroTotalArea) {
  ExpectError(WriteText("flat.off", "OFF\n3 2 0\n0 0 0\n1 1 1\n2 2 2\n3 0 1 2\n3 2 1 0\n"),
              absl::StatusCode::kInvalidArgument,
              "zero total surface area");
}

}  // namespace
}  // namespace meshseek
