#include "common/base/cpu_features.h"

#include <cstdlib>
#include <cstring>

namespace meshseek {
namespace {

SimdLevel Detect() {
  SimdLevel level = SimdLevel::kSse2;
#if defined(__x86_64__) || defined(__i386__)
  __builtin_cpu_init();
  if (__builtin_cpu_supports("avx2")) level = SimdLevel::kAvx2;
  if (__builtin_cpu_supports("avx512f")) level = SimdLevel::kAvx512;
#endif
  if (const char* cap = std::getenv("MESHSEEK_SIMD")) {
    SimdLevel limit = level;
    if (std::strcmp(cap, "sse2") == 0) limit = SimdLevel::kSse2;
    if (std::strcmp(cap, "avx2") == 0) limit = SimdLevel::kAvx2;
    if (static_cast<int>(limit) < static_cast<int>(level)) level = limit;
  }
  return level;
}

}  // namespace

SimdLevel DetectedSimdLevel() {
  static const SimdLevel level = Detect();
  return level;
}

const char* SimdLevelName(SimdLevel level) {
  switch (level) {
    case SimdLevel::kSse2:
      return "sse2";
    case SimdLevel::kAvx2:
      return "avx2";
    case SimdLevel::kAvx512:
      return "avx512";
  }
  return "?";
}

}  // namespace meshseek
