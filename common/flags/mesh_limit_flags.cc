#include "common/flags/mesh_limit_flags.h"

#include <cstdint>

#include "absl/flags/flag.h"
#include "absl/strings/str_cat.h"

namespace {
const meshseek::MeshReadOptions kDefaults;
}

ABSL_FLAG(uint64_t, max_mesh_mb, kDefaults.max_file_bytes >> 20,
          "largest mesh file read or accepted, in MiB");
ABSL_FLAG(uint64_t, max_mesh_vertices, kDefaults.max_vertices,
          "most vertices a mesh may declare or hold");
ABSL_FLAG(uint64_t, max_mesh_triangles, kDefaults.max_triangles,
          "most triangles a mesh may hold after fan triangulation of its polygons");

namespace meshseek::flags {

absl::StatusOr<MeshReadOptions> MeshLimitsFromFlags() {
  MeshReadOptions options;
  const uint64_t mb = absl::GetFlag(FLAGS_max_mesh_mb);
  if (mb == 0 || mb > (uint64_t{1} << 20)) {
    return absl::InvalidArgumentError(
        absl::StrCat("--max_mesh_mb must be in [1, 1048576], got ", mb));
  }
  options.max_file_bytes = mb << 20;
  options.max_vertices = absl::GetFlag(FLAGS_max_mesh_vertices);
  options.max_triangles = absl::GetFlag(FLAGS_max_mesh_triangles);
  if (absl::Status valid = options.Validate(); !valid.ok()) {
    return absl::InvalidArgumentError(absl::StrCat("mesh limit flags: ", valid.message()));
  }
  return options;
}

}  // namespace meshseek::flags
