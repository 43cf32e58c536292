#include "common/geometry/mesh_readers.h"

#include "absl/strings/str_cat.h"

namespace meshseek::mesh_readers {

absl::Status CheckDeclaredSize(absl::string_view declared, uint64_t needed, uint64_t available) {
  if (needed <= available) return absl::OkStatus();
  return absl::InvalidArgumentError(
      absl::StrCat("header declares ",
                   declared,
                   ", but only ",
                   available,
                   " bytes follow (at least ",
                   needed == UINT64_MAX ? "2^64" : absl::StrCat(needed),
                   " needed)"));
}

absl::Status VertexLimitError(absl::string_view where,
                              uint64_t count,
                              const MeshReadOptions& options) {
  return absl::ResourceExhaustedError(absl::StrCat(
      where, ": ", count, " vertices, more than max_vertices (", options.max_vertices, ")"));
}

absl::Status TriangleLimitError(absl::string_view where,
                                uint64_t count,
                                const MeshReadOptions& options) {
  return absl::ResourceExhaustedError(absl::StrCat(where,
                                                   ": ",
                                                   count,
                                                   " triangles after fan triangulation, more than "
                                                   "max_triangles (",
                                                   options.max_triangles,
                                                   ")"));
}

absl::Status ByteError(uint64_t offset, absl::string_view what) {
  return absl::InvalidArgumentError(absl::StrCat("byte ", offset, ": ", what));
}

}  // namespace meshseek::mesh_readers
