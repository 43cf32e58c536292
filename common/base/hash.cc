#include "common/base/hash.h"

namespace meshseek {

uint64_t Fnv1a64(absl::string_view bytes, uint64_t offset_basis) {
  uint64_t hash = offset_basis;
  for (unsigned char b : bytes) {
    hash ^= b;
    hash *= kFnv1a64Prime;
  }
  return hash;
}

}  // namespace meshseek
