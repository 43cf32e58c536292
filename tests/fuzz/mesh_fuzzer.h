// The body shared by the mesh-reader harnesses: parse the bytes with
// ParseMesh as the server does for a MeshFile (default MeshReadOptions), and
// check what every caller relies on when it succeeds.
#ifndef MESHSEEK_TESTS_FUZZ_MESH_FUZZER_H_
#define MESHSEEK_TESTS_FUZZ_MESH_FUZZER_H_

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <optional>

#include "absl/strings/match.h"
#include "absl/strings/string_view.h"
#include "common/geometry/mesh.h"
#include "common/geometry/mesh_io.h"

namespace meshseek::fuzz {

inline void ParseMeshOnce(const uint8_t* data,
                          std::size_t size,
                          absl::string_view name,
                          std::optional<MeshFormat> declared) {
  const absl::string_view bytes(reinterpret_cast<const char*>(data), size);
  MeshReadReport report;
  const absl::StatusOr<TriangleMesh> mesh = ParseMesh(bytes, name, declared, {}, &report);
  if (!mesh.ok()) {
    // Errors start with the name so that a user knows which file failed.
    if (!absl::StartsWith(mesh.status().message(), name)) std::abort();
    return;
  }
  // A mesh handed out is one every algorithm can take.
  if (!ValidateMesh(*mesh).ok()) std::abort();
  (void)report.Summary();
}

}  // namespace meshseek::fuzz

#endif  // MESHSEEK_TESTS_FUZZ_MESH_FUZZER_H_
