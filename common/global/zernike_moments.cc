#include "common/global/zernike_moments.h"

#include <cmath>

#include "absl/strings/str_cat.h"

namespace meshseek {
namespace {

constexpr int kMaxJ = kZernikeMaxOrder / 2;

double Factorial(int n) {
  double f = 1;
  for (int i = 2; i <= n; ++i) f *= i;
  return f;
}

}  // namespace

const std::array<ZernikeIndex, kZernikeCoefficients>& ZernikeIndices() {
  static const std::array<ZernikeIndex, kZernikeCoefficients> indices = [] {
    std::array<ZernikeIndex, kZernikeCoefficients> out;
    int i = 0;
    for (int n = 1; n <= kZernikeMaxOrder; ++n) {
      for (int m = n % 2; m <= n; m += 2) out[i++] = {n, m};
    }
    return out;
  }();
  return indices;
}

SilhouetteCentroid ComputeCentroid(const BinaryImageView& image) {
  SilhouetteCentroid c;
  if (image.pixels == nullptr) return c;
  // Integer sums: exact, so the centroid does not depend on the order.
  int64_t sx = 0, sy = 0;
  for (int y = 0; y < image.height; ++y) {
    const uint8_t* row = image.pixels + static_cast<std::size_t>(y) * image.width;
    for (int x = 0; x < image.width; ++x) {
      if (row[x] == 0) continue;
      sx += x;
      sy += y;
      ++c.pixels;
    }
  }
  if (c.pixels > 0) {
    c.x = static_cast<double>(sx) / c.pixels + 0.5;
    c.y = static_cast<double>(sy) / c.pixels + 0.5;
  }
  return c;
}

double LargestRadius(const BinaryImageView& image, double cx, double cy) {
  double largest = 0;
  if (image.pixels == nullptr) return largest;
  for (int y = 0; y < image.height; ++y) {
    const uint8_t* row = image.pixels + static_cast<std::size_t>(y) * image.width;
    const double dy = y + 0.5 - cy;
    for (int x = 0; x < image.width; ++x) {
      if (row[x] == 0) continue;
      const double dx = x + 0.5 - cx;
      largest = std::max(largest, dx * dx + dy * dy);
    }
  }
  return std::sqrt(largest);
}

absl::StatusOr<std::array<double, kZernikeCoefficients>> ZernikeMagnitudes(
    const BinaryImageView& image, double cx, double cy, double radius) {
  if (image.pixels == nullptr || image.width <= 0 || image.height <= 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("zernike: empty image (", image.width, " x ", image.height, ")"));
  }
  if (!(radius > 0) || !std::isfinite(radius) || !std::isfinite(cx) || !std::isfinite(cy)) {
    return absl::InvalidArgumentError(
        absl::StrCat("zernike: radius must be positive and finite, got ",
                     radius,
                     " (centre ",
                     cx,
                     ", ",
                     cy,
                     ")"));
  }
  // S_jm = sum (r^2)^j conj(z)^m, real and imaginary parts.
  double sr[kMaxJ + 1][kZernikeMaxOrder + 1] = {};
  double si[kMaxJ + 1][kZernikeMaxOrder + 1] = {};
  int64_t inside = 0;
  const double inverse = 1.0 / radius;
  // Pixels on the rim (r = 1 up to rounding) belong to the disc.
  const double kRim = 1 + 1e-12;
  for (int y = 0; y < image.height; ++y) {
    const uint8_t* row = image.pixels + static_cast<std::size_t>(y) * image.width;
    const double py = (y + 0.5 - cy) * inverse;
    for (int x = 0; x < image.width; ++x) {
      if (row[x] == 0) continue;
      const double px = (x + 0.5 - cx) * inverse;
      const double r2 = px * px + py * py;
      if (r2 > kRim) continue;
      ++inside;
      // p = conj(z)^m, m = 0, 1, ...
      double pr = 1, pi = 0;
      for (int m = 0; m <= kZernikeMaxOrder; ++m) {
        double qr = pr, qi = pi;
        for (int j = 0; 2 * j + m <= kZernikeMaxOrder; ++j) {
          sr[j][m] += qr;
          si[j][m] += qi;
          qr *= r2;
          qi *= r2;
        }
        const double nr = pr * px + pi * py;  // (pr + i pi)(px - i py)
        pi = pi * px - pr * py;
        pr = nr;
      }
    }
  }
  std::array<double, kZernikeCoefficients> out{};
  if (inside == 0) return out;
  const double a00 = static_cast<double>(inside);  // R_00 = 1: the pixel count
  const auto& indices = ZernikeIndices();
  for (int i = 0; i < kZernikeCoefficients; ++i) {
    const int n = indices[i].n, m = indices[i].m;
    double ar = 0, ai = 0;
    for (int k = 0; k <= (n - m) / 2; ++k) {
      const double c = ((k % 2) ? -1 : 1) * Factorial(n - k) /
                       (Factorial(k) * Factorial((n + m) / 2 - k) * Factorial((n - m) / 2 - k));
      const int j = (n - m) / 2 - k;
      ar += c * sr[j][m];
      ai += c * si[j][m];
    }
    out[i] = std::hypot(ar, ai) / a00;
  }
  return out;
}

}  // namespace meshseek
