#include "common/global/lfd.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <limits>

#include "absl/strings/str_cat.h"
#include "common/base/parallel.h"
#include "common/render/view_renderer.h"

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#define MESHSEEK_LFD_HAVE_AVX2_KERNEL 1
#endif

namespace meshseek {
namespace {

// View-to-view L1 distances (at most 48 x 255 = 12,240: int16). Row i is
// a-view i; within it the b-view j = 10 lb + k (light field lb, view k) is
// at column 10 k + lb, so that the ten b light fields sit side by side and
// a rotation's sums for all ten are one pass of vector additions
// (MinimumScalar, MinimumAvx2).
// Padded by 6 entries: the vector kernel reads 16 lanes where 10 are used.
using ViewTable = std::array<int16_t, kLfdViews * kLfdViews + 6>;
constexpr int Column(int j) {
  return (j % kLfdViewsPerLightField) * kLfdLightFields + j / kLfdViewsPerLightField;
}

void ViewTableScalar(const uint8_t* a, const uint8_t* b, ViewTable* table) {
  for (int i = 0; i < kLfdViews; ++i) {
    const uint8_t* va = a + i * kLfdViewStride;
    for (int j = 0; j < kLfdViews; ++j) {
      const uint8_t* vb = b + j * kLfdViewStride;
      int sum = 0;
      // All 48 bytes, padding included, as the SIMD kernel does.
      for (int k = 0; k < kLfdViewStride; ++k) sum += std::abs(int{va[k]} - int{vb[k]});
      (*table)[i * kLfdViews + Column(j)] = static_cast<int16_t>(sum);
    }
  }
}

#if defined(MESHSEEK_LFD_HAVE_AVX2_KERNEL)
// One view is a 32-byte and a 16-byte load; _mm256_sad_epu8 / _mm_sad_epu8
// leave 64-bit partial sums of absolute byte differences, added up here.
// Integer arithmetic: the same result as the scalar loop, bit for bit.
__attribute__((target("avx2"))) void ViewTableAvx2(const uint8_t* a,
                                                   const uint8_t* b,
                                                   ViewTable* table) {
  for (int i = 0; i < kLfdViews; ++i) {
    const uint8_t* va = a + i * kLfdViewStride;
    const __m256i a0 = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(va));
    const __m128i a1 = _mm_loadu_si128(reinterpret_cast<const __m128i*>(va + 32));
    int16_t* row = table->data() + i * kLfdViews;
    for (int j = 0; j < kLfdViews; ++j) {
      const uint8_t* vb = b + j * kLfdViewStride;
      const __m256i s =
          _mm256_sad_epu8(a0, _mm256_loadu_si256(reinterpret_cast<const __m256i*>(vb)));
      const __m128i t =
          _mm_sad_epu8(a1, _mm_loadu_si128(reinterpret_cast<const __m128i*>(vb + 32)));
      const __m128i u = _mm_add_epi64(
          _mm_add_epi64(_mm256_castsi256_si128(s), _mm256_extracti128_si256(s, 1)), t);
      row[Column(j)] = static_cast<int16_t>(_mm_cvtsi128_si32(u) + _mm_extract_epi32(u, 2));
    }
  }
}
#endif

// offsets[p][i]: where, from the entry of a-view 10 la and b-view 10 lb,
// rotation p finds the distance of a-view 10 la + i to b-view
// 10 lb + perm_p(i).
struct PermutationOffsets {
  std::array<std::array<uint16_t, kLfdViewsPerLightField>, kLfdCameraRotations> offsets;
};

const PermutationOffsets& Offsets() {
  static const PermutationOffsets table = [] {
    PermutationOffsets t;
    const std::vector<ViewPermutation>& perms = ViewPermutations();
    for (int p = 0; p < kLfdCameraRotations; ++p) {
      for (int i = 0; i < kLfdViewsPerLightField; ++i) {
        t.offsets[p][i] = static_cast<uint16_t>(i * kLfdViews + Column(perms[p][i]));
      }
    }
    return t;
  }();
  return table;
}

// The minimum over light-field pairs (la, lb) and rotations p of
// sum_i table[a-view 10 la + i][b-view 10 lb + perm_p(i)]. For fixed la, p
// and i the ten lb are ten adjacent entries (the layout above), so one pass
// over (la, p, i) sums all ten b light fields at once, in vector lanes.
int MinimumScalar(const ViewTable& table) {
  const PermutationOffsets& o = Offsets();
  int best = std::numeric_limits<int>::max();
  for (int la = 0; la < kLfdLightFields; ++la) {
    const int16_t* base = table.data() + la * kLfdViewsPerLightField * kLfdViews;
    for (int p = 0; p < kLfdCameraRotations; ++p) {
      int sum[kLfdLightFields] = {};
      for (int i = 0; i < kLfdViewsPerLightField; ++i) {
        const int16_t* entries = base + o.offsets[p][i];
        for (int lb = 0; lb < kLfdLightFields; ++lb) sum[lb] += entries[lb];
      }
      best = std::min(best, *std::min_element(sum, sum + kLfdLightFields));
    }
  }
  return best;
}

#if defined(MESHSEEK_LFD_HAVE_AVX2_KERNEL)
// The same with 16 unsigned 16-bit lanes (10 used), adding with saturation
// at 65,535: the minimum is exact whenever it is below that, and otherwise
// (descriptors almost nothing alike) the exact scalar code decides, so both
// paths return the same integer.
__attribute__((target("avx2"))) int MinimumAvx2(const ViewTable& table) {
  const PermutationOffsets& o = Offsets();
  __m256i best = _mm256_set1_epi16(-1);
  for (int la = 0; la < kLfdLightFields; ++la) {
    const int16_t* base = table.data() + la * kLfdViewsPerLightField * kLfdViews;
    for (int p = 0; p < kLfdCameraRotations; ++p) {
      const auto& off = o.offsets[p];
      __m256i sum = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(base + off[0]));
      for (int i = 1; i < kLfdViewsPerLightField; ++i) {
        sum = _mm256_adds_epu16(
            sum, _mm256_loadu_si256(reinterpret_cast<const __m256i*>(base + off[i])));
      }
      best = _mm256_min_epu16(best, sum);
    }
  }
  alignas(32) uint16_t lanes[16];
  _mm256_store_si256(reinterpret_cast<__m256i*>(lanes), best);
  const int m = *std::min_element(lanes, lanes + kLfdLightFields);
  return m < 65535 ? m : MinimumScalar(table);
}
#endif

bool UseAvx2(SimdLevel level) {
#if defined(MESHSEEK_LFD_HAVE_AVX2_KERNEL)
  return static_cast<int>(level) >= static_cast<int>(SimdLevel::kAvx2) &&
         static_cast<int>(DetectedSimdLevel()) >= static_cast<int>(SimdLevel::kAvx2);
#else
  (void)level;
  return false;
#endif
}

// Writes the block of one silhouette (`centroid` its ComputeCentroid) with
// the Zernike disc of `radius`; zeros when nothing is covered.
absl::Status DescribeView(const BinaryImageView& image,
                          const SilhouetteCentroid& centroid,
                          double radius,
                          const ContourFourierOptions& fourier_options,
                          uint8_t* block) {
  if (centroid.pixels == 0) return absl::OkStatus();  // sees nothing: zeros
  // A silhouette of one pixel has radius 0 about its centroid: any positive
  // radius then describes it (all its moments vanish but A_00).
  if (!(radius > 0)) radius = 1;
  absl::StatusOr<std::array<double, kZernikeCoefficients>> zernike =
      ZernikeMagnitudes(image, centroid.x, centroid.y, radius);
  if (!zernike.ok()) return zernike.status();
  absl::StatusOr<std::array<double, kFourierCoefficients>> fourier =
      CentroidDistanceFourier(OuterContour(image), {centroid.x, centroid.y}, fourier_options);
  if (!fourier.ok()) return fourier.status();
  for (int k = 0; k < kZernikeCoefficients; ++k) {
    block[k] = QuantizeLfdCoefficient((*zernike)[k], kLfdZernikeScale);
  }
  for (int k = 0; k < kFourierCoefficients; ++k) {
    block[kZernikeCoefficients + k] = QuantizeLfdCoefficient((*fourier)[k], kLfdFourierScale);
  }
  return absl::OkStatus();
}

}  // namespace

absl::Status LfdOptions::Validate() const {
  if (image_size < 32 || image_size > 1024) {
    return absl::InvalidArgumentError(
        absl::StrCat("lfd: image_size must be in [32, 1024], got ", image_size));
  }
  if (zernike_radius != LfdZernikeRadius::kPerView &&
      zernike_radius != LfdZernikeRadius::kPerLightField) {
    return absl::InvalidArgumentError(
        absl::StrCat("lfd: zernike_radius has no meaning: ", static_cast<int>(zernike_radius)));
  }
  ContourFourierOptions fourier;
  fourier.samples = contour_samples;
  if (absl::Status s = fourier.Validate(); !s.ok()) {
    return absl::InvalidArgumentError(absl::StrCat("lfd: contour_samples: ", s.message()));
  }
  return absl::OkStatus();
}

uint8_t QuantizeLfdCoefficient(double value, double scale) {
  const double q = std::floor(scale * value);
  if (!(q > 0)) return 0;  // negative, zero or NaN
  return q >= 255 ? 255 : static_cast<uint8_t>(q);
}

absl::StatusOr<std::vector<uint8_t>> ExtractLfd(const TriangleMesh& mesh,
                                                const LfdOptions& options) {
  if (absl::Status s = options.Validate(); !s.ok()) return s;
  if (absl::Status s = ValidateMesh(mesh); !s.ok()) {
    return absl::InvalidArgumentError(absl::StrCat("lfd: ", s.message()));
  }
  ViewRenderOptions render_options;
  render_options.image_size = options.image_size;
  absl::StatusOr<ViewRenderer> renderer = ViewRenderer::Create(mesh, render_options);
  if (!renderer.ok()) {
    return absl::InvalidArgumentError(absl::StrCat("lfd: ", renderer.status().message()));
  }
  ContourFourierOptions fourier_options;
  fourier_options.samples = options.contour_samples;
  const std::array<Vec3d, kLfdViewsPerLightField> directions = LightFieldViewDirections();
  const std::array<Rotation3, kLfdLightFields>& rotations = LightFieldRotations();
  const int n = options.image_size;

  std::vector<uint8_t> out(kLfdDescriptorBytes, 0);
  std::array<std::vector<uint8_t>, kLfdViewsPerLightField> masks;
  std::array<SilhouetteCentroid, kLfdViewsPerLightField> centroids;
  for (int l = 0; l < kLfdLightFields; ++l) {
    // The light field's 10 silhouettes first: they may share one Zernike
    // radius.
    std::array<double, kLfdViewsPerLightField> radii;
    double shared = 0;
    for (int v = 0; v < kLfdViewsPerLightField; ++v) {
      masks[v] = renderer->RenderSilhouette(Rotate(rotations[l], directions[v]));
      const BinaryImageView image{masks[v].data(), n, n};
      centroids[v] = ComputeCentroid(image);
      radii[v] = LargestRadius(image, centroids[v].x, centroids[v].y);
      shared = std::max(shared, radii[v]);
    }
    for (int v = 0; v < kLfdViewsPerLightField; ++v) {
      uint8_t* block = out.data() + (l * kLfdViewsPerLightField + v) * kLfdViewStride;
      const double radius =
          options.zernike_radius == LfdZernikeRadius::kPerView ? radii[v] : shared;
      if (absl::Status s = DescribeView({masks[v].data(), n, n}, centroids[v], radius,
                                        fourier_options, block);
          !s.ok()) {
        return s;
      }
    }
  }
  return out;
}

absl::StatusOr<std::array<uint8_t, kLfdViewStride>> DescribeLfdSilhouette(
    const BinaryImageView& silhouette, const LfdOptions& options) {
  if (absl::Status s = options.Validate(); !s.ok()) return s;
  if (silhouette.pixels == nullptr || silhouette.width <= 0 || silhouette.height <= 0) {
    return absl::InvalidArgumentError("lfd: an empty image has no silhouette to describe");
  }
  ContourFourierOptions fourier_options;
  fourier_options.samples = options.contour_samples;
  const SilhouetteCentroid centroid = ComputeCentroid(silhouette);
  std::array<uint8_t, kLfdViewStride> block{};
  if (absl::Status s =
          DescribeView(silhouette, centroid, LargestRadius(silhouette, centroid.x, centroid.y),
                       fourier_options, block.data());
      !s.ok()) {
    return s;
  }
  return block;
}

float LfdViewDistance(const uint8_t* view, const uint8_t* descriptor) {
  int best = std::numeric_limits<int>::max();
  for (int v = 0; v < kLfdViews; ++v) {
    const uint8_t* other = descriptor + v * kLfdViewStride;
    int sum = 0;
    for (int k = 0; k < kLfdCoefficientsPerView; ++k) sum += std::abs(view[k] - other[k]);
    best = std::min(best, sum);
  }
  return static_cast<float>(best);
}

absl::Status ValidateLfdDescriptor(const std::vector<uint8_t>& descriptor) {
  if (descriptor.size() != kLfdDescriptorBytes) {
    return absl::InvalidArgumentError(absl::StrCat(
        "lfd descriptor: ", descriptor.size(), " bytes, expected ", kLfdDescriptorBytes));
  }
  for (int v = 0; v < kLfdViews; ++v) {
    for (int k = kLfdCoefficientsPerView; k < kLfdViewStride; ++k) {
      if (descriptor[v * kLfdViewStride + k] != 0) {
        return absl::InvalidArgumentError(
            absl::StrCat("lfd descriptor: padding byte ", k, " of view ", v, " is not zero"));
      }
    }
  }
  return absl::OkStatus();
}

namespace internal {

float LfdDistanceAtLevel(const uint8_t* a, const uint8_t* b, SimdLevel level) {
  ViewTable table;
  std::fill(table.begin() + kLfdViews * kLfdViews, table.end(), int16_t{0});
#if defined(MESHSEEK_LFD_HAVE_AVX2_KERNEL)
  if (UseAvx2(level)) {
    ViewTableAvx2(a, b, &table);
    return static_cast<float>(MinimumAvx2(table));
  }
#endif
  (void)level;
  ViewTableScalar(a, b, &table);
  return static_cast<float>(MinimumScalar(table));
}

}  // namespace internal

float LfdDistance(const uint8_t* a, const uint8_t* b) {
  return internal::LfdDistanceAtLevel(a, b, DetectedSimdLevel());
}

absl::StatusOr<std::vector<float>> LfdDistanceMatrix(
    const std::vector<std::vector<uint8_t>>& descriptors, int num_threads) {
  for (std::size_t i = 0; i < descriptors.size(); ++i) {
    if (absl::Status s = ValidateLfdDescriptor(descriptors[i]); !s.ok()) {
      return absl::InvalidArgumentError(absl::StrCat("model ", i, ": ", s.message()));
    }
  }
  const std::size_t n = descriptors.size();
  std::vector<float> out(n * n, 0.0f);
  // Row i computes the pairs (i, j > i): the longest rows are handed out
  // first, so the threads finish together.
  ParallelFor(n, num_threads, [&](std::size_t i) {
    for (std::size_t j = i + 1; j < n; ++j) {
      const float d = LfdDistance(descriptors[i].data(), descriptors[j].data());
      out[i * n + j] = d;
      out[j * n + i] = d;
    }
  });
  return out;
}

}  // namespace meshseek
