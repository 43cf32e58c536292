// Which vector instructions this CPU offers, for the few kernels that pick an
// implementation at run time (nearest_centroid.cc).
//
// Binaries are built for baseline x86-64 (SSE2), so that one build and one
// container image run on any x86-64 machine; a kernel that gains from wider
// vectors carries a variant compiled for that target (GCC's target attribute)
// and calls it when the CPU has it. Every such variant computes the same
// floating-point operations in the same order as the baseline one (wider
// vectors over independent lanes, no fused multiply-add), so results never
// depend on the machine.
//
// MESHSEEK_SIMD=sse2|avx2|avx512 in the environment caps the level (to compare
// variants in one benchmark run, or to rule a variant out); it never raises it
// above what the CPU has.
#ifndef MESHSEEK_COMMON_BASE_CPU_FEATURES_H_
#define MESHSEEK_COMMON_BASE_CPU_FEATURES_H_

// Compiles the function it precedes for AVX-512 and AVX2 as well as the
// baseline, the loader picking one for the CPU (GCC's and clang's
// target_clones). The baseline alone is compiled where that cannot work:
// clang before 15 names the dispatcher "<name>.ifunc", so that a call from
// another file does not link (the fuzz build); under ThreadSanitizer the
// dispatcher is instrumented and runs while the loader relocates, before the
// TSan runtime exists, and crashes (the TSan build).
// (__has_feature is clang's: GCC cannot even parse it, hence the nesting.)
#if defined(__clang__)
#if __clang_major__ < 15 || __has_feature(thread_sanitizer)
#define MESHSEEK_NO_TARGET_CLONES 1
#endif
#elif defined(__SANITIZE_THREAD__)
#define MESHSEEK_NO_TARGET_CLONES 1
#endif
#if defined(MESHSEEK_NO_TARGET_CLONES)
#define MESHSEEK_TARGET_CLONES_AVX
#else
#define MESHSEEK_TARGET_CLONES_AVX __attribute__((target_clones("avx512f", "avx2", "default")))
#endif

namespace meshseek {

enum class SimdLevel {
  kSse2 = 0,    ///< baseline x86-64, and every other architecture
  kAvx2 = 1,    ///< 256-bit vectors (Intel Haswell, AMD Zen and later)
  kAvx512 = 2,  ///< 512-bit vectors, AVX-512F (Intel Skylake-SP, AMD Zen 4 and later)
};

/// The widest level this CPU supports, capped by MESHSEEK_SIMD; read once.
SimdLevel DetectedSimdLevel();

/// "sse2", "avx2" or "avx512".
const char* SimdLevelName(SimdLevel level);

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_BASE_CPU_FEATURES_H_
