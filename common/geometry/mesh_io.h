// Reading and writing triangle meshes: OFF, OBJ, PLY and STL, ASCII and binary.
//
// Reading is meshseek's own: one parser per format (off_reader.cc,
// obj_reader.cc, ply_reader.cc, stl_reader.cc) over the whole file held in
// memory, each delivering a polygon soup that one routine (mesh_io.cc) turns
// into a TriangleMesh. No format library is involved: polygon soups,
// non-manifold faces and several components must survive whole, every repair
// must be reported, and a hostile or broken file must fail fast, naming the
// place, without unbounded allocation. What a file holds is repaired and
// counted in MeshReadReport as follows:
//   - polygons with more than 3 corners are fan-triangulated;
//   - corners that repeat the previous corner are removed; a face left with
//     fewer than 3 distinct corners is dropped;
//   - zero-area triangles are kept (they carry no samples) and counted;
//   - STL's per-triangle corners are merged into shared vertices by exact
//     position, numbered in the order first seen.
//
// Format: by content where the content is recognised (DetectMeshFormat), else
// as declared (the extension); a disagreement is noted in the report ("content
// is OFF although the name says OBJ"). Supported: OFF in all of Geomview's
// variants ([ST][C][N][4][n]OFF, ASCII, and OFF BINARY in little-endian as
// meshseek and OpenMesh write it or Geomview's big-endian); OBJ (v and f; the
// i, i/t, i/t/n, i//n and negative corner forms; other statements ignored);
// PLY ascii, binary_little_endian and binary_big_endian with any scalar and
// list types and any other elements and properties; STL binary and ASCII.
//
// Errors, each "<name>: <where>: <what>", <where> being "line N" in text,
// "byte N" in binary data, or "vertex i" / "face j" (0-based):
//   - NotFound: ReadMesh cannot open the file;
//   - ResourceExhausted: the file or mesh is larger than a MeshReadOptions
//     limit (the message names the limit);
//   - InvalidArgument: everything else: an unknown format, malformed or
//     truncated content, a header whose counts the bytes cannot hold
//     ("header declares 4000000000 vertices and 2 faces, but only 37 bytes
//     follow"), a number that is not finite or out of range ("line 4:
//     non-finite coordinate 'nan'"), a vertex index out of range, content after
//     an OFF file's declared faces, and a mesh that fails ValidateMesh (no
//     faces, zero or non-finite area, coordinates beyond the float range).
//
// Bounds (the Redis/SQLite habit): each declared count is checked against the
// bytes present and against the limits before anything is allocated, totals
// are checked while reading, size arithmetic saturates. Memory is a small
// multiple of the file size. Thread-safe (no shared state).
//
// Writing is meshseek's own small, exact code; it exists for the synthetic
// benchmark and for tests, and writes the mesh as given (soups stay soups).
#ifndef MESHSEEK_COMMON_GEOMETRY_MESH_IO_H_
#define MESHSEEK_COMMON_GEOMETRY_MESH_IO_H_

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "common/geometry/mesh.h"

namespace meshseek {

enum class MeshFormat { kOff, kObj, kPly, kStl };

// Format from the file extension (case-insensitive), or InvalidArgument
// "<path>: unknown mesh format 'xyz' (expected .off, .obj, .ply or .stl)".
absl::StatusOr<MeshFormat> MeshFormatFromPath(absl::string_view path);
const char* MeshFormatName(MeshFormat format);

// The format the bytes are in, judged from the content alone, or nullopt:
//   - OFF: the header keyword ([ST][C][N][4][n]OFF, possibly "... BINARY") as
//     the first token after blank and '#' comment lines;
//   - PLY: the magic line "ply";
//   - STL: a binary file of exactly 84 + 50 n bytes (n the count at byte 80,
//     whatever its header says, even "solid ..."), or "solid" followed by
//     "facet" or "endsolid";
//   - OBJ: a first statement (after blank and comment lines) v, vn, vt, vp, f,
//     o, g, s, usemtl, mtllib, l or p.
std::optional<MeshFormat> DetectMeshFormat(absl::string_view bytes);

// Limits on what a read may take; a file beyond them is refused with
// ResourceExhausted naming the limit, before its data is allocated.
struct MeshReadOptions {
  /// Largest file, in bytes, that ReadMesh reads and ParseMesh accepts (the
  /// file is held whole in memory, and the mesh takes a small multiple).
  uint64_t max_file_bytes = uint64_t{1} << 30;
  /// Most vertices a file may declare or hold (at most 2^32 - 1: triangles
  /// store 32-bit indices).
  uint64_t max_vertices = uint64_t{1} << 25;
  /// Most triangles after fan triangulation, a polygon of n corners counting
  /// n - 2 (before repairs; at most 2^32 - 1).
  uint64_t max_triangles = uint64_t{1} << 25;

  // OK, or InvalidArgument naming the bad field and value.
  absl::Status Validate() const;
};

// What ReadMesh / ParseMesh found and did. Counts refer to the file's faces
// (polygons) and to the triangles of the returned mesh.
struct MeshReadReport {
  MeshFormat format = MeshFormat::kOff;   // the format actually parsed
  std::size_t file_vertices = 0;          // vertices the reader delivered
  std::size_t file_faces = 0;             // faces (polygons) the reader delivered
  std::size_t polygons_triangulated = 0;  // faces with > 3 corners split into a fan
  std::size_t faces_repaired = 0;         // faces that had repeated corners removed
  std::size_t faces_dropped = 0;          // faces with < 3 distinct corners
  std::size_t zero_area_triangles = 0;    // kept, but they get no samples
  MeshTopologyStats topology;             // components, boundary, non-manifold edges
  // Facts worth a reader's attention, e.g. "content is OFF although the name
  // says OBJ", "big-endian OFF BINARY (Geomview)", "12 bytes after the STL
  // triangles ignored".
  std::vector<std::string> notes;

  // One line, e.g. "642 vertices, 1280 faces, 1 component, 2 polygons
  // triangulated, content is OFF although the name says OBJ".
  std::string Summary() const;
};

// Parses a whole mesh file held in memory. `name` (a path or a client's file
// name) starts every error message. `declared` is the format the name claims
// (nullopt: unknown); the content decides where it is recognisable.
absl::StatusOr<TriangleMesh> ParseMesh(absl::string_view bytes,
                                       absl::string_view name,
                                       std::optional<MeshFormat> declared,
                                       const MeshReadOptions& options = {},
                                       MeshReadReport* report = nullptr);

// Reads the file at `path` (its size checked against options.max_file_bytes
// before it is read) and parses it with ParseMesh, the extension declaring the
// format. An unknown extension is an error unless the content is recognised.
absl::StatusOr<TriangleMesh> ReadMesh(const std::string& path,
                                      MeshReadReport* report = nullptr,
                                      const MeshReadOptions& options = {});

struct MeshWriteOptions {
  // Binary encoding where the format has one (OFF, PLY, STL); OBJ is always ASCII.
  bool binary = false;
};

// Writes `mesh` in the format given by the extension of `path`.
absl::Status WriteMesh(const std::string& path,
                       const TriangleMesh& mesh,
                       const MeshWriteOptions& options = {});

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_GEOMETRY_MESH_IO_H_
