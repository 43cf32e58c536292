// ParseMesh on bytes that claim to be STL (by name and declared format); the
// content still decides where it is recognisably another format.
#include "tests/fuzz/mesh_fuzzer.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  meshseek::fuzz::ParseMeshOnce(data, size, "fuzz.stl", meshseek::MeshFormat::kStl);
  return 0;
}
