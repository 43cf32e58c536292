// Content detection: DetectMeshFormat, then ParseMesh with no declared format
// (a MeshFile whose name has no known extension), which must agree with the
// detection: unrecognised content is refused, recognised content is parsed as
// what was detected.
#include <cstdlib>

#include "tests/fuzz/mesh_fuzzer.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const absl::string_view bytes(reinterpret_cast<const char*>(data), size);
  const std::optional<meshseek::MeshFormat> detected = meshseek::DetectMeshFormat(bytes);
  meshseek::MeshReadReport report;
  const absl::StatusOr<meshseek::TriangleMesh> mesh =
      meshseek::ParseMesh(bytes, "upload", std::nullopt, {}, &report);
  if (!mesh.ok()) {
    if (!absl::StartsWith(mesh.status().message(), "upload")) std::abort();
    return 0;
  }
  if (!detected || report.format != *detected) std::abort();
  if (!meshseek::ValidateMesh(*mesh).ok()) std::abort();
  return 0;
}
