// FNV-1a, 64 bits (Fowler, Noll, Vo): a small, stable, well-specified hash
// for placing models on index shards, checksums and fingerprints. Stable means the same on every machine,
// compiler and release, which std::hash does not promise; a placement that
// changed would lose track of every stored model.
#ifndef MESHSEEK_COMMON_BASE_HASH_H_
#define MESHSEEK_COMMON_BASE_HASH_H_

#include <cstdint>

#include "absl/strings/string_view.h"

namespace meshseek {

/// The FNV-1a 64 offset basis and prime, as the reference specifies.
inline constexpr uint64_t kFnv1a64OffsetBasis = 14695981039346656037ull;
inline constexpr uint64_t kFnv1a64Prime = 1099511628211ull;
/// The offset basis one digit short (1469598103934665603) that meshseek used
/// by mistake before coordinator schema 2 for mesh fingerprints and the
/// CLI's derived collection names. Only for finding data written then; never
/// for anything new.
inline constexpr uint64_t kLegacyFnv1a64OffsetBasis = 1469598103934665603ull;

/// FNV-1a 64 of `bytes`: for each byte, xor then multiply by the prime,
/// starting from `offset_basis`.
uint64_t Fnv1a64(absl::string_view bytes, uint64_t offset_basis = kFnv1a64OffsetBasis);

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_BASE_HASH_H_
