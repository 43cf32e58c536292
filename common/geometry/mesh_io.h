// Reading and writing triangle meshes: OFF, OBJ, PLY and STL, ASCII and binary.
//
// Reading goes through OpenMesh's format readers with meshseek's own importer
// (mesh_io.cc), not through an OpenMesh mesh kernel: the kernel refuses
// non-manifold faces and silently drops bad ones, whereas meshseek must keep
// polygon soups and several components whole and must report every repair.
// What the importer receives is checked and repaired as follows:
//   - polygons with more than 3 corners are fan-triangulated;
//   - corners that repeat the previous corner are removed; a face left with
//     fewer than 3 distinct corners is dropped;
//   - zero-area triangles are kept (they carry no samples) and counted.
// Everything done is counted in MeshReadReport. These are errors, each named
// with the file and the offending vertex, face or line: a file that cannot be
// opened or parsed, an unknown extension, a non-finite coordinate, a vertex
// index out of range, no faces, zero total area.
//
// Writing is meshseek's own (small, exact) code; it exists for the synthetic
// benchmark and for tests, and writes the mesh as given (soups stay soups).
#ifndef MESHSEEK_COMMON_GEOMETRY_MESH_IO_H_
#define MESHSEEK_COMMON_GEOMETRY_MESH_IO_H_

#include <cstddef>
#include <string>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "common/geometry/mesh.h"

namespace meshseek {

enum class MeshFormat { kOff, kObj, kPly, kStl };

// Format from the file extension (case-insensitive), or InvalidArgument.
absl::StatusOr<MeshFormat> MeshFormatFromPath(absl::string_view path);
const char* MeshFormatName(MeshFormat format);

// What ReadMesh found and did. Counts refer to the file's faces (polygons) and
// to the triangles of the returned mesh.
struct MeshReadReport {
  std::size_t file_vertices = 0;          // vertices the reader delivered
  std::size_t file_faces = 0;             // faces (polygons) the reader delivered
  std::size_t polygons_triangulated = 0;  // faces with > 3 corners split into a fan
  std::size_t faces_repaired = 0;         // faces that had repeated corners removed
  std::size_t faces_dropped = 0;          // faces with < 3 distinct corners
  std::size_t zero_area_triangles = 0;    // kept, but they get no samples
  MeshTopologyStats topology;             // components, boundary, non-manifold edges

  // One line, e.g. "26k triangles, 3 components, 2 polygons triangulated".
  std::string Summary() const;
};

// Reads a mesh file. Errors carry "<path>: <problem>". Thread-safe (OpenMesh's
// readers keep state, so reads are serialised internally).
absl::StatusOr<TriangleMesh> ReadMesh(const std::string& path, MeshReadReport* report = nullptr);

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
