// MeshFromProto on a MeshInput parsed from the bytes, as a service receives it
// (arrays or a MeshFile); a mesh it accepts survives the round trip exactly.
#include <cstdint>
#include <cstdlib>

#include "common/wire/convert.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  meshseek::v1::MeshInput input;
  if (!input.ParseFromArray(data, static_cast<int>(size))) return 0;
  const absl::StatusOr<meshseek::TriangleMesh> mesh = meshseek::wire::MeshFromProto(input);
  if (!mesh.ok()) return 0;
  if (!meshseek::ValidateMesh(*mesh).ok()) std::abort();
  meshseek::v1::MeshInput back;
  meshseek::wire::MeshToProto(*mesh, back.mutable_mesh());
  const absl::StatusOr<meshseek::TriangleMesh> again = meshseek::wire::MeshFromProto(back);
  if (!again.ok() || again->triangles != mesh->triangles ||
      again->vertices.size() != mesh->vertices.size()) {
    std::abort();
  }
  return 0;
}
