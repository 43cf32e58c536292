// FNV-1a, 64 bits (Fowler, Noll, Vo): a small, stable, well-specified hash
// for placing models on index shards. Stable means the same on every machine,
// compiler and release, which std::hash does not promise; a placement that
// changed would lose track of every stored model.
#ifndef MESHSEEK_COMMON_BASE_HASH_H_
#define MESHSEEK_COMMON_BASE_HASH_H_

#include <cstdint>

#include "absl/strings/string_view.h"

namespace meshseek {

/// FNV-1a 64 of `bytes` (offset basis 14695981039346656037, prime
/// 1099511628211).
uint64_t Fnv1a64(absl::string_view bytes);

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_BASE_HASH_H_
