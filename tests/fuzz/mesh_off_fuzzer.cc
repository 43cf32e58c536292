// ParseMesh on bytes that claim to be OFF (by name and declared format); the
// content still decides where it is recognisably another format.
#include "tests/fuzz/mesh_fuzzer.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  meshseek::fuzz::ParseMeshOnce(data, size, "fuzz.off", meshseek::MeshFormat::kOff);
  return 0;
}
