#include "common/bof/nearest_centroid.h"

#include <algorithm>
#include <cstring>
#include <limits>

#if defined(__x86_64__)
#include <immintrin.h>
#endif

#include "common/base/cpu_features.h"
#include "common/base/parallel.h"

namespace meshseek {
namespace {

// A block of 8 points against a panel of 16 centroids: 128 dot products.
constexpr std::size_t kPanelWidth = 16;
constexpr std::size_t kBlockRows = 8;
// Points per ParallelFor item. Fixed, so the split never depends on the thread
// count; large enough that a tile of centroids is reused many times.
constexpr std::size_t kPointsPerTask = 128;
// Bytes of packed centroids searched before moving to the next tile; sized to
// stay resident in a 512 KiB..2 MiB L2 next to the block of points.
constexpr std::size_t kTileBytes = 256 * 1024;

// GCC/Clang generic vector types. They pin the vectorisation to the centroid
// lanes: GCC 12's loop vectoriser, given the kernel as plain nested loops,
// vectorises the dimension loop instead (interleaved loads and shuffles) and
// runs at under a third of the speed (10 against 36 GFLOP/s measured for
// V = 1,000, dim 128, SSE2).
typedef float Float4 __attribute__((vector_size(16)));
typedef float Float8 __attribute__((vector_size(32)));
typedef float Float16 __attribute__((vector_size(64)));
// Loads and stores go through a pointer to an unaligned, aliasing copy of the
// type: GCC turns a std::memcpy into an array of vectors into stack round
// trips.
template <typename Vec>
struct Unaligned {
  typedef Vec type __attribute__((aligned(4), may_alias));
};

// Bit l of the result: a[l] < b[l] (lanes of one vector).
#if defined(__x86_64__)
__attribute__((always_inline)) inline uint32_t LessMask(Float4 a, Float4 b) {
  return static_cast<uint32_t>(_mm_movemask_ps(_mm_cmplt_ps(__m128(a), __m128(b))));
}
__attribute__((target("avx2"), always_inline)) inline uint32_t LessMask(Float8 a, Float8 b) {
  return static_cast<uint32_t>(_mm256_movemask_ps(_mm256_cmp_ps(__m256(a), __m256(b), _CMP_LT_OQ)));
}
__attribute__((target("avx512f"), always_inline)) inline uint32_t LessMask(Float16 a, Float16 b) {
  return static_cast<uint32_t>(_mm512_cmp_ps_mask(__m512(a), __m512(b), _CMP_LT_OQ));
}
#else
template <typename Vec>
inline uint32_t LessMask(Vec a, Vec b) {
  uint32_t mask = 0;
  for (std::size_t l = 0; l < sizeof(Vec) / sizeof(float); ++l) mask |= uint32_t{a[l] < b[l]} << l;
  return mask;
}
#endif

// For the kBlockRows rows of `x` (each `dim` floats) and the kPanelWidth
// centroids of `panel` (dim x kPanelWidth, squared norms `norms`):
// scores[r][l] = norms[l] - 2 x[r].c_l, the dot product summed in increasing
// dimension. `Vec` holds some of a
// panel's lanes; kRows rows are done per pass, so that the pass's
// accumulators (kRows x lanes per Vec) fit the registers of the target. Every
// lane does the same multiply and adds as every other variant, in the same
// order.
template <typename Vec, std::size_t kRows>
__attribute__((always_inline)) inline void PanelScoresBody(const float* x,
                                                           std::size_t dim,
                                                           const float* panel,
                                                           const float* norms,
                                                           float* scores) {
  using Loaded = typename Unaligned<Vec>::type;
  constexpr std::size_t kLanes = sizeof(Vec) / sizeof(float);
  constexpr std::size_t kVectors = kPanelWidth / kLanes;
  for (std::size_t r0 = 0; r0 < kBlockRows; r0 += kRows) {
    Vec acc[kRows][kVectors] = {};
    for (std::size_t d = 0; d < dim; ++d) {
      const Loaded* p = reinterpret_cast<const Loaded*>(panel + d * kPanelWidth);
      for (std::size_t r = 0; r < kRows; ++r) {
        const float xv = x[(r0 + r) * dim + d];
        for (std::size_t v = 0; v < kVectors; ++v) acc[r][v] += xv * p[v];
      }
    }
    for (std::size_t r = 0; r < kRows; ++r) {
      for (std::size_t v = 0; v < kVectors; ++v) {
        *reinterpret_cast<Loaded*>(scores + (r0 + r) * kPanelWidth + v * kLanes) =
            *reinterpret_cast<const Loaded*>(norms + v * kLanes) - 2.0f * acc[r][v];
      }
    }
  }
}

// masks[r] bit l: scores[r][l] < thresholds[r]. Written out in each variant
// (a template cannot inline a target-specific LessMask).
#define MESHSEEK_PANEL_MASKS(Vec)                                                     \
  do {                                                                                \
    using Loaded = Unaligned<Vec>::type;                                              \
    constexpr std::size_t kLanes = sizeof(Vec) / sizeof(float);                       \
    for (std::size_t r = 0; r < kBlockRows; ++r) {                                    \
      const Vec threshold = Vec{} + thresholds[r];                                    \
      uint32_t mask = 0;                                                              \
      for (std::size_t v = 0; v < kPanelWidth / kLanes; ++v) {                        \
        const Vec score =                                                             \
            *reinterpret_cast<const Loaded*>(scores + r * kPanelWidth + v * kLanes);  \
        mask |= LessMask(score, threshold) << (v * kLanes);                           \
      }                                                                               \
      masks[r] = mask;                                                                \
    }                                                                                 \
  } while (false)

// The variants: scores (with 2 x 4 SSE registers of accumulators, 4 x 2 AVX2
// ones, 8 x 1 AVX-512 ones, of 16, 16 and 32 registers), and masks[r] with bit
// l set when scores[r][l] < thresholds[r], so that callers look only at lanes
// that can matter.
void PanelScoresSse2(const float* x,
                     std::size_t dim,
                     const float* panel,
                     const float* norms,
                     const float* thresholds,
                     float* scores,
                     uint32_t* masks) {
  PanelScoresBody<Float4, 2>(x, dim, panel, norms, scores);
  MESHSEEK_PANEL_MASKS(Float4);
}
#if defined(__x86_64__)
__attribute__((target("avx2"))) void PanelScoresAvx2(const float* x,
                                                     std::size_t dim,
                                                     const float* panel,
                                                     const float* norms,
                                                     const float* thresholds,
                                                     float* scores,
                                                     uint32_t* masks) {
  PanelScoresBody<Float8, 4>(x, dim, panel, norms, scores);
  MESHSEEK_PANEL_MASKS(Float8);
}
__attribute__((target("avx512f"))) void PanelScoresAvx512(const float* x,
                                                         std::size_t dim,
                                                         const float* panel,
                                                         const float* norms,
                                                         const float* thresholds,
                                                         float* scores,
                                                         uint32_t* masks) {
  PanelScoresBody<Float16, 8>(x, dim, panel, norms, scores);
  MESHSEEK_PANEL_MASKS(Float16);
}
#endif
#undef MESHSEEK_PANEL_MASKS

using PanelScoresFn = void (*)(const float*, std::size_t, const float*, const float*,
                               const float*, float*, uint32_t*);

PanelScoresFn PanelScoresFor(SimdLevel level) {
#if defined(__x86_64__)
  if (level == SimdLevel::kAvx512) return PanelScoresAvx512;
  if (level == SimdLevel::kAvx2) return PanelScoresAvx2;
#endif
  (void)level;
  return PanelScoresSse2;
}

}  // namespace

NearestCentroidIndex::NearestCentroidIndex(const float* centroids,
                                           std::size_t num_centroids,
                                           std::size_t dim,
                                           SimdLevel simd)
    : num_centroids_(num_centroids),
      dim_(dim),
      simd_(static_cast<int>(simd) < static_cast<int>(DetectedSimdLevel()) ? simd
                                                                          : DetectedSimdLevel()) {
  const std::size_t panels = (num_centroids + kPanelWidth - 1) / kPanelWidth;
  packed_.assign(panels * dim * kPanelWidth, 0.0f);
  norms_.assign(panels * kPanelWidth, std::numeric_limits<float>::infinity());
  for (std::size_t c = 0; c < num_centroids; ++c) {
    const float* row = centroids + c * dim;
    float* panel = &packed_[(c / kPanelWidth) * dim * kPanelWidth];
    double norm = 0.0;
    for (std::size_t d = 0; d < dim; ++d) {
      panel[d * kPanelWidth + c % kPanelWidth] = row[d];
      norm += static_cast<double>(row[d]) * row[d];
    }
    norms_[c] = static_cast<float>(norm);
  }
}

void NearestCentroidIndex::Search(const float* points,
                                  std::size_t n,
                                  int num_threads,
                                  uint32_t* labels,
                                  float* squared_distances) const {
  SearchImpl(points, n, num_threads, labels, squared_distances);
}

void NearestCentroidIndex::Search(const uint8_t* points,
                                  std::size_t n,
                                  int num_threads,
                                  uint32_t* labels,
                                  float* squared_distances) const {
  SearchImpl(points, n, num_threads, labels, squared_distances);
}

template <typename T>
void NearestCentroidIndex::SearchImpl(const T* points,
                                      std::size_t n,
                                      int num_threads,
                                      uint32_t* labels,
                                      float* squared_distances) const {
  const std::size_t dim = dim_;
  const std::size_t panel_floats = dim * kPanelWidth;
  const std::size_t num_panels = norms_.size() / kPanelWidth;
  const std::size_t tile_panels =
      std::max<std::size_t>(1, kTileBytes / (panel_floats * sizeof(float)));
  const std::size_t num_tasks = (n + kPointsPerTask - 1) / kPointsPerTask;
  const PanelScoresFn panel_scores = PanelScoresFor(simd_);

  ParallelFor(num_tasks, num_threads, [&](std::size_t task) {
    const std::size_t begin = task * kPointsPerTask;
    const std::size_t count = std::min(kPointsPerTask, n - begin);
    const std::size_t rows = (count + kBlockRows - 1) / kBlockRows * kBlockRows;
    // A float copy padded to whole row blocks (padding rows are zero and their
    // results are dropped); for uint8 input this is also the conversion.
    std::vector<float> x(rows * dim, 0.0f);
    for (std::size_t i = 0; i < count * dim; ++i)
      x[i] = static_cast<float>(points[begin * dim + i]);

    std::vector<float> best(rows, std::numeric_limits<float>::infinity());
    std::vector<uint32_t> best_label(rows, 0);
    float scores[kBlockRows][kPanelWidth];
    uint32_t masks[kBlockRows];
    for (std::size_t tile = 0; tile < num_panels; tile += tile_panels) {
      const std::size_t tile_end = std::min(num_panels, tile + tile_panels);
      for (std::size_t r0 = 0; r0 < rows; r0 += kBlockRows) {
        for (std::size_t p = tile; p < tile_end; ++p) {
          panel_scores(&x[r0 * dim], dim, &packed_[p * panel_floats], &norms_[p * kPanelWidth],
                       &best[r0], &scores[0][0], masks);
          for (std::size_t r = 0; r < kBlockRows; ++r) {
            // Lanes below the best so far, in increasing index; only a
            // strictly smaller score replaces the best, so ties go to the
            // lowest index (centroids are visited in increasing index).
            for (uint32_t m = masks[r]; m != 0; m &= m - 1) {
              const unsigned l = static_cast<unsigned>(__builtin_ctz(m));
              if (scores[r][l] < best[r0 + r]) {
                best[r0 + r] = scores[r][l];
                best_label[r0 + r] = static_cast<uint32_t>(p * kPanelWidth + l);
              }
            }
          }
        }
      }
    }

    for (std::size_t i = 0; i < count; ++i) {
      labels[begin + i] = best_label[i];
      if (squared_distances == nullptr) continue;
      double norm = 0.0;
      for (std::size_t d = 0; d < dim; ++d)
        norm += static_cast<double>(x[i * dim + d]) * x[i * dim + d];
      squared_distances[begin + i] = std::max(0.0f, static_cast<float>(norm) + best[i]);
    }
  });
}

void NearestCentroidIndex::SearchTopK(const float* points,
                                      std::size_t n,
                                      std::size_t k,
                                      uint32_t* labels,
                                      float* scores) const {
  k = std::min(k, num_centroids_);
  if (k == 0 || n == 0) return;
  const std::size_t dim = dim_;
  const std::size_t panel_floats = dim * kPanelWidth;
  const std::size_t num_panels = norms_.size() / kPanelWidth;
  const std::size_t tile_panels =
      std::max<std::size_t>(1, kTileBytes / (panel_floats * sizeof(float)));
  // Called once per probed group and block by the approximate search (tens
  // of thousands of times per k-means iteration), so nothing is copied or
  // allocated per call except the last, partial row block, padded with zeros.
  const PanelScoresFn panel_scores = PanelScoresFor(simd_);
  const std::size_t full_rows = n / kBlockRows * kBlockRows;
  std::vector<float> tail;
  if (full_rows < n) {
    tail.assign(kBlockRows * dim, 0.0f);
    std::copy_n(points + full_rows * dim, (n - full_rows) * dim, tail.begin());
  }
  std::fill_n(scores, n * k, std::numeric_limits<float>::infinity());
  std::fill_n(labels, n * k, 0u);
  float block_scores[kBlockRows][kPanelWidth];
  uint32_t masks[kBlockRows];
  float thresholds[kBlockRows];
  for (std::size_t tile = 0; tile < num_panels; tile += tile_panels) {
    const std::size_t tile_end = std::min(num_panels, tile + tile_panels);
    for (std::size_t r0 = 0; r0 < n; r0 += kBlockRows) {
      const float* x = r0 < full_rows ? points + r0 * dim : tail.data();
      const std::size_t rows = std::min(kBlockRows, n - r0);
      for (std::size_t p = tile; p < tile_end; ++p) {
        // Each row's current k-th score: lanes at or above it cannot enter.
        for (std::size_t r = 0; r < kBlockRows; ++r) {
          thresholds[r] = r < rows ? scores[(r0 + r) * k + k - 1] : 0.0f;
        }
        panel_scores(x, dim, &packed_[p * panel_floats], &norms_[p * kPanelWidth], thresholds,
                     &block_scores[0][0], masks);
        for (std::size_t r = 0; r < rows; ++r) {
          float* b = scores + (r0 + r) * k;
          uint32_t* bl = labels + (r0 + r) * k;
          for (uint32_t m = masks[r]; m != 0; m &= m - 1) {
            // Same score and strict comparison as SearchImpl, lanes in
            // increasing index; a new entry goes after the equal ones, which
            // have lower indices.
            const unsigned l = static_cast<unsigned>(__builtin_ctz(m));
            const float score = block_scores[r][l];
            if (!(score < b[k - 1])) continue;
            std::size_t j = k - 1;
            for (; j > 0 && score < b[j - 1]; --j) {
              b[j] = b[j - 1];
              bl[j] = bl[j - 1];
            }
            b[j] = score;
            bl[j] = static_cast<uint32_t>(p * kPanelWidth + l);
          }
        }
      }
    }
  }
}

}  // namespace meshseek
