// The format readers behind ParseMesh (mesh_io.h), one source file each
// (off_reader.cc, obj_reader.cc, ply_reader.cc, stl_reader.cc), and what they
// share. Internal to common/geometry; callers use ParseMesh / ReadMesh.
//
// A reader turns a whole file held in memory into a PolygonSoup: positions and
// polygons as they are in the file, indices unchecked, so that ParseMesh's one
// conversion routine does every check, repair and count the same way for all
// formats. A reader's job is the syntax, and the bounds:
//   - every count a header declares is checked against the bytes that follow
//     (a minimum size per record) and against MeshReadOptions before anything
//     is reserved, and reserve() is only ever asked for what the bytes can hold;
//   - while reading, the vertex total and the triangle total (a polygon of n
//     corners counts n - 2) are checked against the limits;
//   - sizes are computed with saturating arithmetic (no overflow).
// Errors carry no file name (ParseMesh adds it): "line N: ..." for text,
// "byte N: ..." for binary. Codes: InvalidArgument for anything malformed,
// truncated or lying; ResourceExhausted for a MeshReadOptions limit.
#ifndef MESHSEEK_COMMON_GEOMETRY_MESH_READERS_H_
#define MESHSEEK_COMMON_GEOMETRY_MESH_READERS_H_

#include <cstdint>
#include <cstring>
#include <string>
#include <type_traits>
#include <vector>

#include "absl/status/status.h"
#include "absl/strings/string_view.h"
#include "common/geometry/mesh_io.h"
#include "common/geometry/vec3.h"

namespace meshseek::mesh_readers {

struct PolygonSoup {
  std::vector<Vec3f> positions;
  // Every polygon's corners, concatenated: 0-based vertex indices as the file
  // gives them (signed and 64-bit, so that a bad one stays visible).
  std::vector<int64_t> corners;
  // Polygon f is corners[f == 0 ? 0 : face_ends[f - 1] .. face_ends[f]).
  std::vector<uint64_t> face_ends;
  // Sum over polygons of max(0, corners - 2): the fan triangles, checked
  // against MeshReadOptions::max_triangles while reading.
  uint64_t triangles = 0;
  // What the reader wants MeshReadReport::notes to say (e.g. "big-endian OFF
  // BINARY (Geomview)", "12 bytes after the STL triangles ignored").
  std::vector<std::string> notes;

  // Closes the polygon whose corners were appended since the last one; false
  // when the triangle total now exceeds `max_triangles`.
  bool EndFace(uint64_t max_triangles) {
    const uint64_t begin = face_ends.empty() ? 0 : face_ends.back();
    const uint64_t n = corners.size() - begin;
    face_ends.push_back(corners.size());
    if (n > 2) triangles += n - 2;
    return triangles <= max_triangles;
  }
};

absl::Status ReadOff(absl::string_view bytes, const MeshReadOptions& options, PolygonSoup* soup);
absl::Status ReadObj(absl::string_view bytes, const MeshReadOptions& options, PolygonSoup* soup);
absl::Status ReadPly(absl::string_view bytes, const MeshReadOptions& options, PolygonSoup* soup);
absl::Status ReadStl(absl::string_view bytes, const MeshReadOptions& options, PolygonSoup* soup);

// Content detection helpers (DetectMeshFormat).
// Geomview's OFF keyword: [ST][C][N][4][n]OFF, e.g. OFF, COFF, NOFF, CNOFF, STOFF, 4OFF, nOFF.
struct OffKeyword {
  bool texcoords = false;    // ST: two texture coordinates per vertex
  bool colours = false;      // C: a colour per vertex
  bool normals = false;      // N: a normal per vertex
  bool homogeneous = false;  // 4: x y z w
  bool dimension = false;    // n: the header gives the dimension
};
bool ParseOffKeyword(absl::string_view token, OffKeyword* keyword);
// 84 + 50 n bytes, n the triangle count at byte 80 (whatever the header says).
bool HasBinaryStlSize(absl::string_view bytes);
// "solid" and then "facet" or "endsolid" as the next token.
bool LooksLikeAsciiStl(absl::string_view bytes);

// --- Bounds.

inline uint64_t SaturatingAdd(uint64_t a, uint64_t b) {
  uint64_t sum;
  return __builtin_add_overflow(a, b, &sum) ? UINT64_MAX : sum;
}
inline uint64_t SaturatingMul(uint64_t a, uint64_t b) {
  uint64_t product;
  return __builtin_mul_overflow(a, b, &product) ? UINT64_MAX : product;
}

// InvalidArgument "header declares <declared>, but only <available> bytes
// follow (at least <needed> needed)" when needed > available.
absl::Status CheckDeclaredSize(absl::string_view declared, uint64_t needed, uint64_t available);
// ResourceExhausted naming the limit: "<where>: 1001 vertices, more than
// max_vertices (1000)"; `where` is "header", "line 7" or "byte 84".
absl::Status VertexLimitError(absl::string_view where,
                              uint64_t count,
                              const MeshReadOptions& options);
absl::Status TriangleLimitError(absl::string_view where,
                                uint64_t count,
                                const MeshReadOptions& options);

// InvalidArgument "byte N: <what>".
absl::Status ByteError(uint64_t offset, absl::string_view what);

// --- Binary input.

// Reads fixed-size little- or big-endian scalars from a byte buffer. The reads
// are unchecked: the caller asks Has(n) first (once per record, not per value).
class ByteCursor {
 public:
  ByteCursor(absl::string_view bytes, std::size_t offset, bool big_endian)
      : bytes_(bytes), pos_(offset), big_endian_(big_endian) {}

  bool Has(uint64_t n) const { return n <= remaining(); }
  std::size_t remaining() const { return bytes_.size() - pos_; }
  std::size_t offset() const { return pos_; }
  bool big_endian() const { return big_endian_; }
  const char* here() const { return bytes_.data() + pos_; }
  void Skip(std::size_t n) { pos_ += n; }

  template <typename T>
  T Read() {
    const T value = Load<T>(here(), big_endian_);
    pos_ += sizeof(T);
    return value;
  }

  // The scalar at `p` in the given byte order.
  template <typename T>
  static T Load(const char* p, bool big_endian) {
    static_assert(sizeof(T) == 1 || sizeof(T) == 2 || sizeof(T) == 4 || sizeof(T) == 8);
    if constexpr (sizeof(T) == 1) {
      T value;
      std::memcpy(&value, p, 1);
      return value;
    } else {
      using Bits = std::conditional_t<sizeof(T) == 2,
                                      uint16_t,
                                      std::conditional_t<sizeof(T) == 4, uint32_t, uint64_t>>;
      Bits bits;
      std::memcpy(&bits, p, sizeof(T));
      // meshseek targets little-endian hosts (x86-64, aarch64).
      if (big_endian) {
        if constexpr (sizeof(T) == 2) bits = __builtin_bswap16(bits);
        if constexpr (sizeof(T) == 4) bits = __builtin_bswap32(bits);
        if constexpr (sizeof(T) == 8) bits = __builtin_bswap64(bits);
      }
      T value;
      std::memcpy(&value, &bits, sizeof(T));
      return value;
    }
  }

 private:
  absl::string_view bytes_;
  std::size_t pos_;
  bool big_endian_;
};

}  // namespace meshseek::mesh_readers

#endif  // MESHSEEK_COMMON_GEOMETRY_MESH_READERS_H_
