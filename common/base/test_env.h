// What a test needs to know about the build it runs in (tests only).
//
// Under a sanitizer (scripts/sanitize.sh) code runs 2x (ASan) to 5-15x (TSan)
// slower, and CI runs every case under both: there a test uses the smallest
// data that still checks the same thing (the kills, the bit-identical
// matrices), and stretches its time bounds by kSlowdown.
#ifndef MESHSEEK_COMMON_BASE_TEST_ENV_H_
#define MESHSEEK_COMMON_BASE_TEST_ENV_H_

namespace meshseek {

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
inline constexpr bool kSanitized = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
inline constexpr bool kSanitized = true;
#else
inline constexpr bool kSanitized = false;
#endif
#else
inline constexpr bool kSanitized = false;
#endif

// Factor on a test's own time bounds (a deadline, a latency it asserts).
inline constexpr int kSlowdown = kSanitized ? 10 : 1;

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_BASE_TEST_ENV_H_
