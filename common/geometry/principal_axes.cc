#include "common/geometry/principal_axes.h"

#include <algorithm>
#include <cmath>

namespace meshseek {

void SymmetricEigen3(const std::array<std::array<double, 3>, 3>& matrix,
                     std::array<double, 3>* eigenvalues,
                     std::array<Vec3d, 3>* eigenvectors) {
  double a[3][3], v[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) a[i][j] = matrix[i][j];
  }
  for (int sweep = 0; sweep < 50; ++sweep) {
    const double off = a[0][1] * a[0][1] + a[0][2] * a[0][2] + a[1][2] * a[1][2];
    const double diag = a[0][0] * a[0][0] + a[1][1] * a[1][1] + a[2][2] * a[2][2];
    if (off <= 1e-30 * diag || off == 0) break;
    for (int p = 0; p < 2; ++p) {
      for (int q = p + 1; q < 3; ++q) {
        if (a[p][q] == 0) continue;
        // Rotation that zeroes a[p][q] (Numerical Recipes' jacobi, stable form).
        const double theta = (a[q][q] - a[p][p]) / (2 * a[p][q]);
        const double t =
            (theta >= 0 ? 1.0 : -1.0) / (std::abs(theta) + std::sqrt(theta * theta + 1));
        const double c = 1 / std::sqrt(t * t + 1), s = t * c;
        for (int k = 0; k < 3; ++k) {  // A <- A J
          const double akp = a[k][p], akq = a[k][q];
          a[k][p] = c * akp - s * akq;
          a[k][q] = s * akp + c * akq;
        }
        for (int k = 0; k < 3; ++k) {  // A <- J^T A
          const double apk = a[p][k], aqk = a[q][k];
          a[p][k] = c * apk - s * aqk;
          a[q][k] = s * apk + c * aqk;
        }
        for (int k = 0; k < 3; ++k) {  // V <- V J
          const double vkp = v[k][p], vkq = v[k][q];
          v[k][p] = c * vkp - s * vkq;
          v[k][q] = s * vkp + c * vkq;
        }
      }
    }
  }
  int order[3] = {0, 1, 2};
  std::sort(order, order + 3, [&](int i, int j) { return a[i][i] > a[j][j]; });
  for (int k = 0; k < 3; ++k) {
    const int c = order[k];
    (*eigenvalues)[k] = a[c][c];
    (*eigenvectors)[k] = Normalized(Vec3d(v[0][c], v[1][c], v[2][c]));
  }
}

namespace {

PrincipalAxes AxesOf(const Vec3d& center, std::array<std::array<double, 3>, 3> cov, double weight) {
  PrincipalAxes result;
  result.centroid = center;
  for (int r = 0; r < 3; ++r) {
    for (int c = r; c < 3; ++c) {
      cov[r][c] /= weight > 0 ? weight : 1.0;
      cov[c][r] = cov[r][c];
    }
  }
  SymmetricEigen3(cov, &result.variances, &result.axes);
  result.axes[2] = Normalized(Cross(result.axes[0], result.axes[1]));
  return result;
}

}  // namespace

PrincipalAxes ComputeWeightedPrincipalAxes(const std::vector<Vec3f>& points,
                                           const std::vector<uint32_t>& subset,
                                           const Vec3d& center,
                                           double radius) {
  std::array<std::array<double, 3>, 3> cov{};
  double total = 0;
  for (const uint32_t i : subset) {
    const Vec3d d = Vec3d(points[i]) - center;
    const double w = std::max(0.0, radius - Norm(d));
    total += w;
    for (int r = 0; r < 3; ++r) {
      for (int c = r; c < 3; ++c) cov[r][c] += w * d[r] * d[c];
    }
  }
  return AxesOf(center, cov, total);
}

PrincipalAxes ComputePrincipalAxes(const std::vector<Vec3f>& points,
                                   const std::vector<uint32_t>* subset) {
  const std::size_t n = subset ? subset->size() : points.size();
  auto at = [&](std::size_t i) { return Vec3d(points[subset ? (*subset)[i] : i]); };
  Vec3d sum;
  for (std::size_t i = 0; i < n; ++i) sum += at(i);
  const Vec3d centroid = n > 0 ? sum / static_cast<double>(n) : Vec3d();
  std::array<std::array<double, 3>, 3> cov{};
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3d d = at(i) - centroid;
    for (int r = 0; r < 3; ++r) {
      for (int c = r; c < 3; ++c) cov[r][c] += d[r] * d[c];
    }
  }
  return AxesOf(centroid, cov, static_cast<double>(n));
}

}  // namespace meshseek
