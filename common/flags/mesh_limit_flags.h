// The flags that bound what a mesh file may make a process allocate
// (MeshReadOptions, common/geometry/mesh_io.h), shared by the services that
// read meshes (coordinator, extract, resample) and the CLI, so that each
// limit has one flag, one default and one validation:
//   --max_mesh_mb        largest mesh file, MiB (default 1024)
//   --max_mesh_vertices  most vertices a mesh may declare or hold (2^25)
//   --max_mesh_triangles most triangles after fan triangulation (2^25)
// A file over a limit is refused with RESOURCE_EXHAUSTED naming the limit; a
// file whose header promises more than its bytes hold is INVALID_ARGUMENT
// whatever the limits.
#ifndef MESHSEEK_COMMON_FLAGS_MESH_LIMIT_FLAGS_H_
#define MESHSEEK_COMMON_FLAGS_MESH_LIMIT_FLAGS_H_

#include "absl/status/statusor.h"
#include "common/geometry/mesh_io.h"

namespace meshseek::flags {

/// MeshReadOptions from the flags, validated (InvalidArgument naming the flag).
absl::StatusOr<MeshReadOptions> MeshLimitsFromFlags();

}  // namespace meshseek::flags

#endif  // MESHSEEK_COMMON_FLAGS_MESH_LIMIT_FLAGS_H_
