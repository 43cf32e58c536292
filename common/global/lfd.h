// The Light Field Descriptor (LFD) of Chen, Tian, Shen & Ouhyoung, "On visual
// similarity based 3D model retrieval" (Eurographics 2003): a global,
// view-based shape descriptor. Two models are alike when they look alike
// from every side, whatever their orientation.
//
// Extraction (ExtractLfd). The model is framed by its minimum enclosing
// sphere (translation and scale drop out). For each of 10 light fields
// (lfd_cameras.h: 10 differently rotated dodecahedra) and each of its 10
// views (one per antipodal vertex pair; the opposite camera sees the mirror
// image, which the descriptors cannot tell apart) an orthographic silhouette
// is rendered (common/render/view_renderer.h) and described by
//   - 35 Zernike moment magnitudes up to order 10 (zernike_moments.h),
//     centred on the silhouette's centroid, over the disc whose radius is the
//     silhouette's largest centroid-to-pixel distance (LfdZernikeRadius);
//   - 10 Fourier magnitudes of the outer contour's centroid distance
//     (contour_fourier.h).
// Each coefficient is quantised to 8 bits as the original does:
// q = min(255, floor(s * v)) with s = 256 for Zernike (v in [0, 1]) and
// s = 512 for Fourier (the original's FD_SCALE of 2). On PSB train no byte
// saturates; the median byte is 6 (Zernike) and 10 (Fourier), the 99th
// percentile 139 and 165 (bench/results/lfd.txt). An empty silhouette (a view that sees nothing,
// e.g. a model thinner than a pixel) gives zeros, never NaN.
//
// Descriptor layout (kLfdDescriptorBytes = 4,800 bytes, fixed): light field
// l in 0..9, view v in 0..9, block (10 l + v) of kLfdViewStride = 48 bytes:
// 35 Zernike bytes in ZernikeIndices() order, 10 Fourier bytes (k = 1..10),
// 3 zero bytes of padding (so that a view is one 32- plus one 16-byte load).
//
// Distance (LfdDistance), as the original. Two light fields are compared in
// each of the 60 relative orientations of their camera systems (the
// icosahedral group acting on the 10 views, ViewPermutations): the sum over
// views of the L1 distance of their 45 bytes; the light-field distance is
// the smallest of the 60. The model distance is the smallest light-field
// distance over the 10 x 10 pairs. It is computed as a 100 x 100 table of
// view-to-view L1 distances (SAD) and then 100 x 60 sums of 10 table
// entries, the 10 b light fields side by side in vector lanes. Both steps
// use AVX2 where the CPU has it (_mm256_sad_epu8; 16-bit saturating sums,
// exact below 65,535, the scalar code deciding above), and the scalar path
// gives the same integers. The result is an integer (exact in float),
// symmetric, 0 from a descriptor to itself, and, because the 10 light
// fields cover orientations only at a finite spacing, only approximately
// invariant to rotating the model (lfd_test.cc states by how much).
#ifndef MESHSEEK_COMMON_GLOBAL_LFD_H_
#define MESHSEEK_COMMON_GLOBAL_LFD_H_

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "common/base/cpu_features.h"
#include "common/geometry/mesh.h"
#include "common/global/contour_fourier.h"
#include "common/global/lfd_cameras.h"
#include "common/global/zernike_moments.h"

namespace meshseek {

/// Coefficients per view: 35 Zernike + 10 Fourier.
inline constexpr int kLfdCoefficientsPerView = kZernikeCoefficients + kFourierCoefficients;
/// Bytes per view in the descriptor (45 coefficients + 3 zero bytes).
inline constexpr int kLfdViewStride = 48;
/// Views per model (10 light fields x 10 views).
inline constexpr int kLfdViews = kLfdLightFields * kLfdViewsPerLightField;
/// Size of a serialised descriptor.
inline constexpr std::size_t kLfdDescriptorBytes =
    static_cast<std::size_t>(kLfdViews) * kLfdViewStride;
/// Quantisation scales (q = min(255, floor(scale * value))).
inline constexpr double kLfdZernikeScale = 256;
inline constexpr double kLfdFourierScale = 512;

/// The radius of the disc the Zernike moments of a silhouette are taken over.
enum class LfdZernikeRadius {
  /// The silhouette's own largest centroid-to-pixel distance: each view is
  /// scale-normalised on its own.
  kPerView,
  /// The largest over the light field's 10 silhouettes, as we read the
  /// original (its FindRadius takes the 10 images of a light field): the
  /// views keep their relative sizes. Measured 1.2 to 1.7 points of first
  /// tier below kPerView on McGill and PSB train (bench/results/lfd.txt).
  kPerLightField,
};

struct LfdOptions {
  /// Silhouette side in pixels, 32 to 1024. The paper renders 256 x 256;
  /// 128 retrieves as well on McGill and PSB train at a third of the cost
  /// (bench/results/lfd.txt), hence the default.
  int image_size = 128;
  /// Points the outer contour is resampled to for the Fourier descriptor
  /// (contour_fourier.h; 21 to 65,536).
  int contour_samples = 128;
  /// Zernike disc radius: per view (the default, measured better) or
  /// shared by a light field's views (the original's).
  LfdZernikeRadius zernike_radius = LfdZernikeRadius::kPerView;

  absl::Status Validate() const;
};

/// q = min(255, floor(scale * value)); 0 for a negative or NaN value.
uint8_t QuantizeLfdCoefficient(double value, double scale);

/// The serialised descriptor of `mesh` (kLfdDescriptorBytes bytes).
/// InvalidArgument, the message starting "lfd: ", for bad options or a mesh
/// ValidateMesh rejects (no triangles, an index out of range, a non-finite
/// coordinate, zero area) or whose enclosing sphere has no extent.
/// Deterministic; single-threaded (parallelise across models).
absl::StatusOr<std::vector<uint8_t>> ExtractLfd(const TriangleMesh& mesh,
                                                const LfdOptions& options);

/// One view's block of kLfdViewStride bytes for any silhouette (1 where
/// covered), described as ExtractLfd describes each rendered view: what a
/// picture queries with (picture_silhouette.h). The Zernike disc is the
/// silhouette's own, whatever options.zernike_radius says (a picture has no
/// light field to share one with); the silhouette's position and size do not
/// matter (both descriptors are centred on its centroid and scaled by it).
/// An empty silhouette gives zeros. InvalidArgument for bad options or an
/// empty image.
absl::StatusOr<std::array<uint8_t, kLfdViewStride>> DescribeLfdSilhouette(
    const BinaryImageView& silhouette, const LfdOptions& options);

/// The distance of one view's block (DescribeLfdSilhouette) to a model's
/// descriptor (kLfdDescriptorBytes, not checked): the smallest L1 distance
/// of its 45 coefficients to any of the model's 100 views, so the view that
/// looks most like the picture decides (Chen et al.'s query by one image).
/// The mirror image needs no second search: reflecting a silhouette
/// conjugates its Zernike moments and reverses its contour, neither of which
/// changes a magnitude, so it has the same block. Exact (an integer);
/// thread-safe.
float LfdViewDistance(const uint8_t* view, const uint8_t* descriptor);

/// InvalidArgument unless `descriptor` has kLfdDescriptorBytes bytes with
/// zero padding (a descriptor ExtractLfd wrote). For data read from outside.
absl::Status ValidateLfdDescriptor(const std::vector<uint8_t>& descriptor);

/// The LFD distance of two descriptors of kLfdDescriptorBytes bytes each
/// (not checked: see ValidateLfdDescriptor). Thread-safe; about 17 us
/// with AVX2, 27 us scalar (bench/results/lfd.txt).
float LfdDistance(const uint8_t* a, const uint8_t* b);

/// All pairs: entry i * N + j is LfdDistance(descriptors[i], descriptors[j]),
/// N = descriptors.size(), the diagonal 0. Each unordered pair is computed
/// once (the distance is exactly symmetric); rows are spread over
/// `num_threads` threads (<= 0: all cores); the result does not depend on
/// the thread count. InvalidArgument when a descriptor fails
/// ValidateLfdDescriptor (naming its index).
absl::StatusOr<std::vector<float>> LfdDistanceMatrix(
    const std::vector<std::vector<uint8_t>>& descriptors, int num_threads);

namespace internal {

/// LfdDistance with the SAD kernel chosen by `level` (kAvx2 and above use
/// AVX2 when the CPU has it, otherwise the scalar code): for tests that pin
/// the two paths to the same result, and for benchmarks.
float LfdDistanceAtLevel(const uint8_t* a, const uint8_t* b, SimdLevel level);

}  // namespace internal
}  // namespace meshseek

#endif  // MESHSEEK_COMMON_GLOBAL_LFD_H_
