#include "common/geometry/mesh_io.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>

#include "common/geometry/test_meshes.h"

// The largest single allocation since the last reset (allocation_probe.cc):
// lying headers must be refused before their counts reach reserve().
extern std::atomic<std::size_t> g_largest_allocation;

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
              "line 1: expected the OFF header keyword");
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

// --- Options, content detection, limits.

absl::StatusOr<TriangleMesh> Parse(const std::string& bytes,
                                   const std::string& name,
                                   const MeshReadOptions& options = {},
                                   MeshReadReport* report = nullptr) {
  const absl::StatusOr<MeshFormat> declared = MeshFormatFromPath(name);
  return ParseMesh(bytes,
                   name,
                   declared.ok() ? std::optional<MeshFormat>(*declared) : std::nullopt,
                   options,
                   report);
}

void ExpectParseError(const std::string& bytes,
                      const std::string& name,
                      absl::StatusCode code,
                      const std::string& what,
                      const MeshReadOptions& options = {}) {
  const auto read = Parse(bytes, name, options);
  ASSERT_FALSE(read.ok()) << name;
  EXPECT_EQ(read.status().code(), code) << read.status();
  EXPECT_THAT(std::string(read.status().message()), HasSubstr(name + ": "));
  EXPECT_THAT(std::string(read.status().message()), HasSubstr(what));
}

const char kTetraOff[] =
    "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";

TEST(MeshReadOptionsTest, DefaultsArePinnedAndValid) {
  const MeshReadOptions options;
  EXPECT_EQ(options.max_file_bytes, uint64_t{1} << 30);
  EXPECT_EQ(options.max_vertices, uint64_t{1} << 25);
  EXPECT_EQ(options.max_triangles, uint64_t{1} << 25);
  EXPECT_TRUE(options.Validate().ok()) << options.Validate();
}

TEST(MeshReadOptionsTest, ValidateNamesTheBadFieldAndValue) {
  MeshReadOptions options;
  options.max_vertices = 0;
  EXPECT_THAT(std::string(options.Validate().message()), HasSubstr("max_vertices = 0"));
  options = MeshReadOptions();
  options.max_triangles = uint64_t{1} << 40;
  EXPECT_THAT(std::string(options.Validate().message()),
              HasSubstr("max_triangles = 1099511627776"));
  options = MeshReadOptions();
  options.max_file_bytes = 0;
  EXPECT_THAT(std::string(options.Validate().message()), HasSubstr("max_file_bytes = 0"));
  EXPECT_EQ(Parse(kTetraOff, "t.off", options).status().code(), absl::StatusCode::kInvalidArgument);
}

TEST(DetectMeshFormatTest, RecognisesEachFormatByItsContent) {
  std::string binary_stl = "solid but binary";
  binary_stl.resize(80, ' ');
  binary_stl += std::string("\x01\0\0\0", 4) + std::string(50, '\0');
  const std::vector<std::pair<std::string, std::optional<MeshFormat>>> cases = {
      {"OFF\n3 1 0\n", MeshFormat::kOff},
      {"# made by hand\n\n  COFF 3 1 0\n", MeshFormat::kOff},
      {"NOFF\n", MeshFormat::kOff},
      {"STCN4nOFF\n", MeshFormat::kOff},
      {std::string("OFF BINARY\n\0\0\0\x03", 15), MeshFormat::kOff},
      {"ply\nformat ascii 1.0\n", MeshFormat::kPly},
      {"ply\r\nformat binary_big_endian 1.0\r\n", MeshFormat::kPly},
      {"solid part\n  facet normal 0 0 1\n", MeshFormat::kStl},
      {"solid empty\nendsolid empty\n", MeshFormat::kStl},
      {binary_stl, MeshFormat::kStl},
      {"# exported\nv 1 2 3\n", MeshFormat::kObj},
      {"mtllib scene.mtl\no thing\n", MeshFormat::kObj},
      {"g group\nf 1 2 3\n", MeshFormat::kObj},
      {"hello\n", std::nullopt},
      {"1 2 3\n", std::nullopt},
      {"XOFF\n", std::nullopt},
      {"solid x\nhello\n", std::nullopt},
      {"", std::nullopt},
  };
  for (const auto& [bytes, format] : cases) {
    EXPECT_EQ(DetectMeshFormat(bytes), format) << bytes;
  }
}

TEST(ParseMeshTest, ContentDecidesWhenTheNameDisagreesAndTheReportSaysSo) {
  const std::string path = WriteText("really_off.obj", kTetraOff);
  MeshReadReport report;
  auto read = ReadMesh(path, &report);
  ASSERT_TRUE(read.ok()) << read.status();
  EXPECT_EQ(read->triangles.size(), 4u);
  EXPECT_EQ(report.format, MeshFormat::kOff);
  EXPECT_THAT(report.Summary(), HasSubstr("content is OFF although the name says OBJ"));
}

TEST(ParseMeshTest, UnrecognisedContentIsParsedAsDeclared) {
  ExpectParseError("hello\n",
                   "model.ply",
                   absl::StatusCode::kInvalidArgument,
                   "line 1: expected "
                   "the PLY magic");
  ExpectParseError("hello\n", "model.stl", absl::StatusCode::kInvalidArgument, "binary STL");
}

TEST(ParseMeshTest, WithoutADeclaredFormatTheContentMustBeRecognised) {
  auto read = ParseMesh("1 2 3\n", "upload", std::nullopt);
  ASSERT_FALSE(read.ok());
  EXPECT_EQ(read.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(read.status().message()), HasSubstr("upload: unknown mesh format"));
  MeshReadReport report;
  read = ReadMesh(WriteText("tetra.mesh", kTetraOff), &report);
  ASSERT_TRUE(read.ok()) << read.status();
  EXPECT_THAT(report.Summary(), HasSubstr("content is OFF"));
}

TEST(ParseMeshTest, CoordinatesNearFloatMaxAreRefused) {
  // Finite coordinates, but the area (and in the second file the extent)
  // overflows float, the precision every algorithm works in.
  ExpectParseError("OFF\n3 1 0\n0 0 0\n3e38 0 0\n0 3e38 0\n3 0 1 2\n",
                   "big.off",
                   absl::StatusCode::kInvalidArgument,
                   "total surface area 4.5e+76 overflows float");
  ExpectParseError("OFF\n3 1 0\n-3e38 0 0\n3e38 0 0\n0 1 0\n3 0 1 2\n",
                   "wide.off",
                   absl::StatusCode::kInvalidArgument,
                   "bounding box extent (6e+38, 1, 0) overflows float");
}

TEST(ParseMeshTest, LimitsAreEnforcedAndNamed) {
  MeshReadOptions options;
  options.max_vertices = 3;
  ExpectParseError(kTetraOff,
                   "t.off",
                   absl::StatusCode::kResourceExhausted,
                   "header: 4 vertices, more than max_vertices (3)",
                   options);
  ExpectParseError("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\n",
                   "t.obj",
                   absl::StatusCode::kResourceExhausted,
                   "line 4: 4 vertices, more than max_vertices (3)",
                   options);
  options = MeshReadOptions();
  options.max_triangles = 3;
  ExpectParseError(kTetraOff,
                   "t.off",
                   absl::StatusCode::kResourceExhausted,
                   "line 10: 4 triangles after fan triangulation, more than max_triangles (3)",
                   options);
  // One polygon of 6 corners is 4 triangles.
  ExpectParseError("v 0 0 0\nv 1 0 0\nv 2 1 0\nv 1 2 0\nv 0 2 0\nv -1 1 0\nf 1 2 3 4 5 6\n",
                   "hexagon.obj",
                   absl::StatusCode::kResourceExhausted,
                   "max_triangles (3)",
                   options);
  TriangleMesh cube = testing_meshes::Cube();
  for (const std::string name : {"cube.ply", "cube.stl"}) {
    const std::string path = TempPath(name);
    ASSERT_TRUE(WriteMesh(path, cube, {true}).ok());
    auto read = ReadMesh(path, nullptr, options);
    EXPECT_EQ(read.status().code(), absl::StatusCode::kResourceExhausted) << read.status();
    EXPECT_THAT(std::string(read.status().message()), HasSubstr("max_triangles (3)"));
  }
  options = MeshReadOptions();
  options.max_file_bytes = 10;
  ExpectParseError(kTetraOff,
                   "t.off",
                   absl::StatusCode::kResourceExhausted,
                   "more than max_file_bytes (10)",
                   options);
  auto read = ReadMesh(WriteText("t.off", kTetraOff), nullptr, options);
  EXPECT_EQ(read.status().code(), absl::StatusCode::kResourceExhausted);
  EXPECT_THAT(std::string(read.status().message()), HasSubstr("more than max_file_bytes (10)"));
}

// --- Lying headers: refused at once, before their counts reach an allocation.

std::string LittleEndian32(uint32_t value) {
  std::string bytes(4, '\0');
  std::memcpy(bytes.data(), &value, 4);
  return bytes;
}

TEST(LyingHeaderTest, FailsFastWithoutAHugeAllocation) {
  const std::string ply_binary_head =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
      "property float y\nproperty float z\nelement face 1\n";
  const std::string three_vertices(36, '\0');
  const std::vector<std::tuple<std::string, std::string, std::string>> cases = {
      {"bare.off", "OFF", "line 1: the file ends before the vertex count"},
      {"bare_newline.off", "OFF\n", "line 1: the file ends before the vertex count"},
      {"huge.off",
       "OFF\n4000000000 1 0\n",
       "header declares 4000000000 vertices and 1 faces, but only 0 bytes follow"},
      {"huge_faces.off",
       "OFF\n3 4000000000 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
       "header declares 3 vertices and 4000000000 faces, but only 26 bytes follow"},
      {"huge_face.off",
       "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n4000000000 0 1 2\n",
       "line 6: face 0 declares 4000000000 corners, but the line has 3"},
      {"huge_binary.off",
       "OFF BINARY\n" + LittleEndian32(4000000000u) + LittleEndian32(1) + LittleEndian32(0),
       "header declares 4000000000 vertices and 1 faces, but only 0 bytes follow"},
      {"huge_binary_face.off",
       "OFF BINARY\n" + LittleEndian32(3) + LittleEndian32(1) + LittleEndian32(0) + three_vertices +
           LittleEndian32(0xFFFFFFFFu),
       "face 0 declares 4294967295 corners, but only 0 bytes follow"},
      {"huge.ply",
       "ply\nformat ascii 1.0\nelement vertex 4000000000\nproperty float x\nproperty float y\n"
       "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
       "0 0 0\n",
       "header declares 4000000000 vertex, 1 face records, but only 6 bytes follow"},
      {"huge_binary.ply",
       "ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty double x\n"
       "property double y\nproperty double z\nend_header\n",
       "header declares 4000000000 vertex records, but only 0 bytes follow"},
      {"huge_list.ply",
       ply_binary_head + "property list uint uint vertex_indices\nend_header\n" + three_vertices +
           LittleEndian32(0xFFFFFFFFu),
       "the file ends inside face record 0"},
      {"huge.stl",
       std::string(80, ' ') + LittleEndian32(4000000000u),
       "header declares 4000000000 triangles, but only 0 bytes follow"},
      {"huge_index.obj",
       "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4000000000\n",
       "references vertex 3999999999, but the file has 3 vertices"},
  };
  for (const auto& [name, bytes, what] : cases) {
    g_largest_allocation = 0;
    const auto start = std::chrono::steady_clock::now();
    const auto read = Parse(bytes, name);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const std::size_t largest = g_largest_allocation;
    ASSERT_FALSE(read.ok()) << name;
    EXPECT_EQ(read.status().code(), absl::StatusCode::kInvalidArgument) << read.status();
    EXPECT_THAT(std::string(read.status().message()), HasSubstr(what)) << name;
    EXPECT_LT(seconds, 0.5) << name;
    EXPECT_LT(largest, std::size_t{1} << 16) << name;  // nothing sized by the header
  }
  // The probe works: an honest header's counts are reserved at once.
  std::string honest = "OFF\n10000 1 0\n";
  for (int v = 0; v < 10000; ++v) honest += "0 0 0\n";
  g_largest_allocation = 0;
  EXPECT_FALSE(Parse(honest + "3 0 1 2\n", "honest.off").ok());  // zero area
  EXPECT_GE(g_largest_allocation.load(), 10000 * sizeof(Vec3f));
}

}  // namespace
}  // namespace meshseek
