// The format readers in detail (through ParseMesh): what each format's
// variants read as, the errors they give, and that no prefix or corruption of
// a file can crash or hang them.
#include "common/geometry/mesh_readers.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <limits>
#include <random>

#include "common/base/file_io.h"
#include "common/geometry/mesh_io.h"
#include "common/geometry/test_meshes.h"

namespace meshseek {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;

// Builds binary files value by value, in either byte order.
class Bytes {
 public:
  explicit Bytes(bool big_endian = false) : big_endian_(big_endian) {}
  Bytes& Text(absl::string_view text) {
    data_.append(text.data(), text.size());
    return *this;
  }
  template <typename T>
  Bytes& Put(T value) {
    char raw[sizeof(T)];
    std::memcpy(raw, &value, sizeof(T));
    if (big_endian_) std::reverse(raw, raw + sizeof(T));
    data_.append(raw, sizeof(T));
    return *this;
  }
  template <typename T>
  Bytes& PutAll(std::initializer_list<T> values) {
    for (T v : values) Put(v);
    return *this;
  }
  const std::string& str() const { return data_; }

 private:
  bool big_endian_;
  std::string data_;
};

absl::StatusOr<TriangleMesh> Parse(const std::string& bytes,
                                   const std::string& name,
                                   MeshReadReport* report = nullptr) {
  const absl::StatusOr<MeshFormat> declared = MeshFormatFromPath(name);
  return ParseMesh(
      bytes, name, declared.ok() ? std::optional<MeshFormat>(*declared) : std::nullopt, {}, report);
}

void ExpectError(const std::string& bytes, const std::string& name, const std::string& what) {
  const auto read = Parse(bytes, name);
  ASSERT_FALSE(read.ok()) << name << " read as " << read->triangles.size() << " triangles";
  EXPECT_EQ(read.status().code(), absl::StatusCode::kInvalidArgument) << read.status();
  EXPECT_THAT(std::string(read.status().message()), HasSubstr(name + ": " + what));
}

// The unit right triangle (0,0,0) (1,0,0) (0,1,0), as most tests below read it.
void ExpectUnitTriangle(const absl::StatusOr<TriangleMesh>& read) {
  ASSERT_TRUE(read.ok()) << read.status();
  EXPECT_THAT(read->vertices, ElementsAre(Vec3f(0, 0, 0), Vec3f(1, 0, 0), Vec3f(0, 1, 0)));
  EXPECT_THAT(read->triangles, ElementsAre(Triangle{0, 1, 2}));
}

// --- OFF

TEST(OffReaderTest, CommentsBeforeTheHeaderAndAtLineEnds) {
  ExpectUnitTriangle(
      Parse("# written by hand\n\n# by meshseek's tests\nOFF # the keyword\n"
            "3 1 0 # counts\n0 0 0 # v0\n1 0 0\n\n0 1 0\n# faces\n3 0 1 2 # f0\n"
            "# trailing comment\n\n",
            "comments.off"));
}

TEST(OffReaderTest, CountsOnTheKeywordLineWithoutTheEdgeCountOrWithoutTheKeyword) {
  ExpectUnitTriangle(Parse("OFF 3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", "inline.off"));
  ExpectUnitTriangle(Parse("OFF\n3 1\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2", "noedges.off"));
  ExpectUnitTriangle(Parse("3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", "nokeyword.off"));
  ExpectUnitTriangle(Parse("OFF\r\n3 1 0\r\n0 0 0\r\n1 0 0\r\n0 1 0\r\n3 0 1 2\r\n", "crlf.off"));
}

TEST(OffReaderTest, VertexLinesWithColoursNormalsAndTextureCoordinates) {
  ExpectUnitTriangle(
      Parse("COFF\n3 1 0\n0 0 0 255 0 0 255\n1 0 0 0 255 0 255\n"
            "0 1 0 0 0 255 255\n3 0 1 2 0.5 0.5 0.5\n",
            "colours.off"));
  ExpectUnitTriangle(
      Parse("NOFF\n3 1 0\n0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0 1\n3 0 1 2\n", "normals.off"));
  ExpectUnitTriangle(
      Parse("STCNOFF\n3 1 0\n0 0 0 0 0 1 1 1 1 1 0 0\n1 0 0 0 0 1 1 1 1 1 1 0\n"
            "0 1 0 0 0 1 1 1 1 1 0 1\n3 0 1 2\n",
            "everything.off"));
  // Homogeneous coordinates are divided by w; nOFF gives the dimension first.
  ExpectUnitTriangle(Parse("4OFF\n3 1 0\n0 0 0 1\n2 0 0 2\n0 3 0 3\n3 0 1 2\n", "w.off"));
  ExpectUnitTriangle(Parse("nOFF\n3\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", "dim.off"));
  ExpectError("nOFF 4\n3 1 0\n0 0 0 0\n1 0 0 0\n0 1 0 0\n3 0 1 2\n",
              "dim4.off",
              "line 1: nOFF dimension 4");
}

TEST(OffReaderTest, TruncatedOrMissingFacesAreErrorsNamingTheLine) {
  ExpectError("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1\n",
              "cut.off",
              "line 6: face 0 declares 3 corners, but the line has 2");
  ExpectError("OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
              "few.off",
              "line 6: the file ends after 1 of the 2 declared faces");
  ExpectError("OFF\n4 1 0\n0 0 0\n1 0 0\n0 1 0 # a comment long enough for the size check\n",
              "fewv.off",
              "line 5: the file ends after 3 of the 4 declared vertices");
  ExpectError("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 2 1\n",
              "extra.off",
              "line 7: unexpected '3 0 2 1' after the 1 declared faces");
}

TEST(OffReaderTest, MalformedTokensNameTheLineAndToken) {
  ExpectError("OFF\n3 1 0\n0 0 0\n1 x 0\n0 1 0\n3 0 1 2\n",
              "x.off",
              "line 4: expected x y z, "
              "found 'x'");
  ExpectError("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1\n3 0 1 2\n", "short.off", "line 5: expected x y z");
  ExpectError("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1.5 2\n",
              "index.off",
              "line 6: face 0: expected a vertex index, found '1.5'");
  ExpectError("OFF\n-3 1 0\n", "negative.off", "line 2: expected the vertex count, found '-3'");
  ExpectError("OFF\n3 1 0 7\n", "counts.off", "line 2: unexpected '7' after the counts");
}

TEST(OffReaderTest, BinaryBigEndianAsGeomviewWritesIt) {
  // Geomview: big-endian, and after each face a colour count and that many values.
  Bytes off(/*big_endian=*/true);
  off.Text("OFF BINARY\n").PutAll<int32_t>({3, 2, 0}).PutAll<float>({0, 0, 0, 1, 0, 0, 0, 1, 0});
  off.PutAll<int32_t>({3, 0, 1, 2, 3}).PutAll<float>({1, 0, 0});  // an RGB colour
  off.PutAll<int32_t>({3, 0, 2, 1, 0});                           // no colour
  MeshReadReport report;
  const auto read = Parse(off.str(), "geomview.off", &report);
  ASSERT_TRUE(read.ok()) << read.status();
  EXPECT_THAT(read->vertices, ElementsAre(Vec3f(0, 0, 0), Vec3f(1, 0, 0), Vec3f(0, 1, 0)));
  EXPECT_THAT(read->triangles, ElementsAre(Triangle{0, 1, 2}, Triangle{0, 2, 1}));
  EXPECT_THAT(report.Summary(), HasSubstr("big-endian OFF BINARY"));
}

TEST(OffReaderTest, BinaryLittleEndianWithVertexColoursAndTrailingBytes) {
  Bytes off;
  off.Text("COFF BINARY\n").PutAll<uint32_t>({3, 1, 0});
  off.PutAll<float>({0, 0, 0, /*rgba*/ 0.2f, 0.4f, 0.6f, 1});
  off.PutAll<float>({1, 0, 0, /*rgba*/ 0.2f, 0.4f, 0.6f, 1});
  off.PutAll<float>({0, 1, 0, /*rgba*/ 0.2f, 0.4f, 0.6f, 1});
  off.PutAll<uint32_t>({3, 0, 1, 2}).Text("\n\n");
  MeshReadReport report;
  ExpectUnitTriangle(Parse(off.str(), "coloured.off", &report));
  EXPECT_THAT(report.Summary(), HasSubstr("2 bytes after the faces ignored"));
}

// --- OBJ

TEST(ObjReaderTest, EveryFaceCornerForm) {
  const auto read = Parse(
      "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nvt 0 0\nvt 1 0\nvn 0 0 1\n"
      "f 1/1 2/2 3/1\nf 1//1 2//1 4//1\nf 1/1/1 3/2/1 4/1/1\nf -4/1 -2 -1//1\n",
      "corners.obj");
  ASSERT_TRUE(read.ok()) << read.status();
  EXPECT_THAT(
      read->triangles,
      ElementsAre(Triangle{0, 1, 2}, Triangle{0, 1, 3}, Triangle{0, 2, 3}, Triangle{0, 2, 3}));
}

TEST(ObjReaderTest, CrlfCommentsContinuationsAndIgnoredStatements) {
  ExpectUnitTriangle(
      Parse("# header\r\nmtllib x.mtl\r\no thing\r\ng group\r\ns off\r\n"
            "usemtl red\r\nv 0 0 0 1.0\r\nv 1 0 0 0.5 0.2 0.1 # w, colours\r\n"
            "v 0 1 \\\r\n 0\r\nvp 0.5\r\nl 1 2\r\np 1\r\ncurv 0 1 1 2\r\n"
            "f 1 2 \\\r\n\\\r\n3\r\n",
            "crlf.obj"));
}

TEST(ObjReaderTest, BadIndicesAndCoordinatesNameTheLine) {
  ExpectError("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", "zero.obj", "line 4: vertex index 0");
  ExpectError("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 a 3\n",
              "corner.obj",
              "line 4: expected a face corner (i, i/t, i/t/n or i//n), found 'a'");
  ExpectError("v 1 2\n", "short.obj", "line 1: expected x y z, found the line's end");
  ExpectError("v 0 0 0\nv 1 0 0\nf -3 1 2\n",
              "relative.obj",
              "face 0 (0-based) references vertex -1, but the file has 2 vertices");
}

// --- PLY

TEST(PlyReaderTest, BinaryBigEndianDoublesExtraPropertiesAndElements) {
  Bytes ply(/*big_endian=*/true);
  ply.Text(
      "ply\nformat binary_big_endian 1.0\ncomment made by hand\nobj_info none\n"
      "element vertex 3\nproperty uchar red\nproperty double z\nproperty double x\n"
      "property float confidence\nproperty double y\nproperty list uchar int texture\n"
      "element edge 2\nproperty int vertex1\nproperty int vertex2\nproperty uchar red\n"
      "element face 1\nproperty uchar flags\nproperty list uint8 uint32 vertex_indices\n"
      "property float quality\nproperty list uchar float texcoord\n"
      "element material 1\nproperty float ambient\nend_header\n");
  ply.Put<uint8_t>(1).PutAll<double>({0, 0}).Put<float>(0.5f).Put<double>(0);
  ply.Put<uint8_t>(2).PutAll<int32_t>({7, 8});
  ply.Put<uint8_t>(2).PutAll<double>({0, 1}).Put<float>(0.5f).Put<double>(0).Put<uint8_t>(0);
  ply.Put<uint8_t>(3).PutAll<double>({0.1, 0}).Put<float>(0.5f).Put<double>(1);
  ply.Put<uint8_t>(1).Put<int32_t>(9);
  ply.PutAll<int32_t>({0, 1}).Put<uint8_t>(5).PutAll<int32_t>({1, 2}).Put<uint8_t>(6);
  ply.Put<uint8_t>(0xff).Put<uint8_t>(3).PutAll<uint32_t>({0, 1, 2}).Put<float>(1);
  ply.Put<uint8_t>(6).PutAll<float>({0, 0, 1, 0, 0, 1});
  ply.Put<float>(0.25f);
  const auto read = Parse(ply.str(), "big.ply");
  ASSERT_TRUE(read.ok()) << read.status();
  EXPECT_THAT(read->vertices,
              ElementsAre(Vec3f(0, 0, 0), Vec3f(1, 0, 0), Vec3f(0, 1, static_cast<float>(0.1))));
  EXPECT_THAT(read->triangles, ElementsAre(Triangle{0, 1, 2}));
}

TEST(PlyReaderTest, AsciiWithExtraPropertiesAndElements) {
  ExpectUnitTriangle(Parse(
      "ply\nformat ascii 1.0\ncomment x y z after a normal\nelement vertex 3\n"
      "property float nx\nproperty float x\nproperty float y\nproperty float z\n"
      "property uchar red\nproperty list uchar float uv\nelement edge 1\nproperty int a\n"
      "property int b\nelement face 1\nproperty list uchar int vertex_index\nproperty int flags\n"
      "end_header\n9 0 0 0 255 2 0.5 0.5\n9 1 0 0 255 0\n9 0 1 0 255 1 7\n0 1\n3 0 1 2 42\n",
      "extra.ply"));
}

TEST(PlyReaderTest, EveryScalarTypeName) {
  Bytes ply;
  ply.Text(
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty char a\n"
      "property int8 b\nproperty uchar c\nproperty uint8 d\nproperty short e\nproperty int16 f\n"
      "property ushort g\nproperty uint16 h\nproperty int i\nproperty int32 j\nproperty uint k\n"
      "property uint32 l\nproperty float32 m\nproperty float x\nproperty float64 y\n"
      "property int16 z\nproperty double n\nelement face 1\n"
      "property list ushort int16 vertex_indices\nend_header\n");
  const float xs[3] = {0, 1, 0};
  const double ys[3] = {0, 0, 1};
  for (int v = 0; v < 3; ++v) {
    ply.Put<int8_t>(-1).Put<int8_t>(-2).Put<uint8_t>(3).Put<uint8_t>(4);
    ply.Put<int16_t>(-5).Put<int16_t>(-6).Put<uint16_t>(7).Put<uint16_t>(8);
    ply.Put<int32_t>(-9).Put<int32_t>(-10).Put<uint32_t>(11).Put<uint32_t>(12);
    ply.Put<float>(13).Put<float>(xs[v]).Put<double>(ys[v]).Put<int16_t>(0).Put<double>(14);
  }
  ply.Put<uint16_t>(3).PutAll<int16_t>({0, 1, 2});
  ExpectUnitTriangle(Parse(ply.str(), "types.ply"));
}

TEST(PlyReaderTest, HeaderAndBodyErrors) {
  const std::string head = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n";
  const std::string xyz = head + "property float y\nproperty float z\n";
  ExpectError("plyx\n", "magic.ply", "line 1: expected the PLY magic 'ply'");
  ExpectError("ply\nelement vertex 0\nend_header\n",
              "format.ply",
              "line 3: the header has no "
              "format line");
  ExpectError(
      head + "property int128 y\n", "type.ply", "line 5: expected 'property <type> <name>'");
  ExpectError(head + "end_header\n", "noyz.ply", "line 3: element vertex has no scalar property y");
  ExpectError(xyz + "element face 1\nproperty list uchar int corners\nend_header\n",
              "nolist.ply",
              "line 7: element face has no vertex_indices list");
  ExpectError(xyz, "noend.ply", "line 6: the PLY header has no end_header line");
  ExpectError(xyz +
                  "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
                  "0 0 0\n1 0 0\n0 1 0 5\n3 0 1 2\n",
              "extra.ply",
              "line 12: unexpected '5' after the 3 properties of element vertex");
  ExpectError(xyz +
                  "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
                  "0 0 0\n1 0 0\n0 1 0\n3 0 1\n",
              "short.ply",
              "line 13: face record 0 ends before its property vertex_indices");
}

// --- STL

TEST(StlReaderTest, BinaryWhoseHeaderBeginsWithSolid) {
  Bytes stl;
  std::string header = "solid but in fact binary";
  header.resize(80, ' ');
  stl.Text(header).Put<uint32_t>(2);
  stl.PutAll<float>({0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0}).Put<uint16_t>(0);
  stl.PutAll<float>({0, 0, 1, 1, 0, 0, 1, 1, 0, 0, 1, 0}).Put<uint16_t>(0);
  MeshReadReport report;
  const auto read = Parse(stl.str(), "solid.stl", &report);
  ASSERT_TRUE(read.ok()) << read.status();
  EXPECT_THAT(read->vertices,  // merged, in the order first seen
              ElementsAre(Vec3f(0, 0, 0), Vec3f(1, 0, 0), Vec3f(0, 1, 0), Vec3f(1, 1, 0)));
  EXPECT_THAT(read->triangles, ElementsAre(Triangle{0, 1, 2}, Triangle{1, 3, 2}));
  EXPECT_EQ(report.topology.components, 1u);
}

TEST(StlReaderTest, AsciiMergesEqualPositionsIncludingSignedZero) {
  const auto read = Parse(
      "solid t\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n   vertex 1 0 0\n"
      "   vertex 0 1 0\n  endloop\n endfacet\n facet normal 0 0 -1\n  outer loop\n"
      "   vertex -0 0 0\n   vertex 0 1 0\n   vertex 1 0 -0\n  endloop\n endfacet\nendsolid t\n",
      "ascii.stl");
  ASSERT_TRUE(read.ok()) << read.status();
  EXPECT_EQ(read->vertices.size(), 3u);
  EXPECT_THAT(read->triangles, ElementsAre(Triangle{0, 1, 2}, Triangle{0, 2, 1}));
}

TEST(StlReaderTest, Errors) {
  ExpectError("solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 nan 0\n",
              "nan.stl",
              "line 4: non-finite coordinate 'nan'");
  ExpectError("solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\n",
              "open.stl",
              "line 4: the file ends inside a facet");
  Bytes stl;
  stl.Text(std::string(80, ' ')).Put<uint32_t>(1);
  stl.PutAll<float>({0, 0, 1, 0, 0, 0, 1, 0, 0, 0, std::numeric_limits<float>::infinity(), 0});
  stl.Put<uint16_t>(0);
  ExpectError(stl.str(), "inf.stl", "byte 84: triangle 0 has a non-finite coordinate");
}

// --- Robustness: every prefix, and random corruption, of small files.

struct Sample {
  std::string name;
  std::string bytes;
  bool every_prefix_fails;                       // a prefix of the file is never a valid file...
  std::size_t valid_prefix = std::string::npos;  // ...except this one
};

std::vector<Sample> Samples() {
  const TriangleMesh cube = testing_meshes::Cube();
  std::vector<Sample> samples;
  for (const auto& [ext, binary] : std::vector<std::pair<std::string, bool>>{{"off", true},
                                                                             {"ply", true},
                                                                             {"stl", true},
                                                                             {"off", false},
                                                                             {"ply", false},
                                                                             {"obj", false},
                                                                             {"stl", false}}) {
    const std::string path = ::testing::TempDir() + "/sample_" + (binary ? "bin." : "ascii.") + ext;
    EXPECT_TRUE(WriteMesh(path, cube, {binary}).ok());
    const std::string bytes = ReadFileToString(path).value();
    // OBJ and ASCII STL have no counts: a prefix ending at a face is a smaller mesh.
    samples.push_back({path, bytes, binary || ext == "off" || ext == "ply"});
  }
  Bytes geomview(/*big_endian=*/true);
  geomview.Text("OFF BINARY\n").PutAll<int32_t>({3, 1, 0});
  geomview.PutAll<float>({0, 0, 0, 1, 0, 0, 0, 1, 0}).PutAll<int32_t>({3, 0, 1, 2, 1});
  geomview.Put<float>(0.5f);
  // Cut before its colour count, the file is a valid colour-less OFF BINARY.
  samples.push_back({"geomview.off", geomview.str(), true, geomview.str().size() - 8});
  return samples;
}

TEST(RobustnessTest, EveryPrefixErrorsOrReadsAndNeverCrashes) {
  const auto start = std::chrono::steady_clock::now();
  for (const Sample& sample : Samples()) {
    ASSERT_TRUE(Parse(sample.bytes, sample.name).ok()) << sample.name;
    for (std::size_t length = 0; length < sample.bytes.size(); ++length) {
      const auto read = Parse(sample.bytes.substr(0, length), sample.name);
      // Only the final newline of a text file may go missing.
      const bool may_succeed = !sample.every_prefix_fails || length + 1 == sample.bytes.size() ||
                               length == sample.valid_prefix;
      if (!may_succeed) {
        EXPECT_FALSE(read.ok()) << sample.name << " cut at " << length;
      }
    }
  }
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 5);
}

TEST(RobustnessTest, RandomCorruptionNeverCrashes) {
  std::mt19937 random(7);
  std::size_t read_ok = 0, refused = 0;
  for (const Sample& sample : Samples()) {
    for (int trial = 0; trial < 500; ++trial) {
      std::string bytes = sample.bytes;
      const int flips = 1 + trial % 4;
      for (int k = 0; k < flips; ++k) {
        bytes[random() % bytes.size()] = static_cast<char>(random() % 256);
      }
      (Parse(bytes, sample.name).ok() ? read_ok : refused)++;
    }
  }
  EXPECT_GT(refused, 0u);
  EXPECT_GT(read_ok, 0u);  // e.g. a changed coordinate digit
}

}  // namespace
}  // namespace meshseek
