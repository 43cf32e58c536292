// Zernike moment magnitudes of a binary image (a silhouette), the region
// descriptor of the Light Field Descriptor (Chen et al., Eurographics 2003).
//
// The Zernike polynomial of order n and repetition m (0 <= m <= n, n - m
// even) on the unit disc is V_nm(r, t) = R_nm(r) e^{i m t} with the radial
// polynomial R_nm(r) = sum_{k=0}^{(n-m)/2} (-1)^k (n-k)! /
// (k! ((n+m)/2-k)! ((n-m)/2-k)!) r^{n-2k}. The moment of a silhouette f is
// A_nm = sum over covered pixels of conj(V_nm) at the pixel centre, the
// centre taken relative to (cx, cy) and divided by `radius`. Its magnitude
// does not change when the image turns about (cx, cy) or is mirrored, which
// is why LFD uses magnitudes only.
//
// Orders 0..10 give 36 (n, m) pairs. The descriptor drops (0, 0): |A_00| is
// the pixel count, used as the normaliser, so that every other coefficient
// is |A_nm| / |A_00|. That leaves the paper's 35 coefficients, and matches
// the original implementation, which computes MPEG-7's angular radial
// transform (12 angular x 3 radial = 36 terms) and likewise skips the (0, 0)
// term it normalises by. As there, the polynomials are not scaled by
// (n + 1) / pi: |V_nm| <= 1 on the disc, so each coefficient lies in [0, 1],
// ready for 8-bit quantisation (lfd.h).
//
// Computation: r^{n-2k} e^{-imt} = (r^2)^j conj(z)^m with z = x + iy and
// j = (n-m)/2 - k, so one pass over the pixels accumulates the 36 complex
// sums S_jm = sum (r^2)^j conj(z)^m (2j + m <= 10) and every A_nm is a short
// integer combination of them. Cost: about 40 complex multiply-adds per
// covered pixel.
#ifndef MESHSEEK_COMMON_GLOBAL_ZERNIKE_MOMENTS_H_
#define MESHSEEK_COMMON_GLOBAL_ZERNIKE_MOMENTS_H_

#include <array>
#include <cstdint>

#include "absl/status/statusor.h"

namespace meshseek {

/// Largest order n.
inline constexpr int kZernikeMaxOrder = 10;
/// Coefficients kept: the 36 pairs of orders 0..10 less (0, 0).
inline constexpr int kZernikeCoefficients = 35;

/// Order n and repetition m of coefficient i, in the descriptor's order:
/// n ascending, then m ascending: (1,1), (2,0), (2,2), (3,1), (3,3), ...
struct ZernikeIndex {
  int n = 0;
  int m = 0;
};
const std::array<ZernikeIndex, kZernikeCoefficients>& ZernikeIndices();

/// A binary image, row-major, `width` x `height`; nonzero bytes are covered.
struct BinaryImageView {
  const uint8_t* pixels = nullptr;
  int width = 0;
  int height = 0;
};

/// The centroid (mean of covered pixel centres; pixel (x, y) has its centre
/// at (x + 0.5, y + 0.5)) and the number of covered pixels. The centroid is
/// (0, 0) when nothing is covered.
struct SilhouetteCentroid {
  double x = 0;
  double y = 0;
  int64_t pixels = 0;
};
SilhouetteCentroid ComputeCentroid(const BinaryImageView& image);

/// The largest distance from (cx, cy) to a covered pixel centre (0 when
/// nothing is covered).
double LargestRadius(const BinaryImageView& image, double cx, double cy);

/// |A_nm| / |A_00| for the 35 (n, m) of ZernikeIndices(), pixel centres
/// mapped to ((x + 0.5 - cx) / radius, (y + 0.5 - cy) / radius). Covered
/// pixels outside the unit disc are left out (the polynomials are defined on
/// the disc only); pass radius >= LargestRadius to keep every pixel.
/// An image with no covered pixel inside the disc gives all zeros.
/// InvalidArgument for a null or empty image or a radius that is not
/// positive and finite.
absl::StatusOr<std::array<double, kZernikeCoefficients>> ZernikeMagnitudes(
    const BinaryImageView& image, double cx, double cy, double radius);

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_GLOBAL_ZERNIKE_MOMENTS_H_
