// Principal component analysis of a small 3-D point set: the local frame of
// every LD-SIFT-style descriptor (docs/design.md 2.2, "local tangential plane by
// PCA").
#ifndef MESHSEEK_COMMON_GEOMETRY_PRINCIPAL_AXES_H_
#define MESHSEEK_COMMON_GEOMETRY_PRINCIPAL_AXES_H_

#include <array>
#include <cstdint>
#include <vector>

#include "common/geometry/vec3.h"

namespace meshseek {

struct PrincipalAxes {
  Vec3d centroid;
  // Unit eigenvectors of the covariance, by decreasing eigenvalue: axes[0] is
  // the direction of largest spread, axes[2] of smallest (the normal of the
  // best-fitting plane). Right-handed: axes[2] = axes[0] x axes[1]. The sign
  // of each axis is otherwise arbitrary; callers must not depend on it.
  std::array<Vec3d, 3> axes;
  std::array<double, 3> variances{0, 0, 0};  // eigenvalues, decreasing
};

// PCA of points[i] for i in `subset` (all points if `subset` is null).
// Requires at least one point.
PrincipalAxes ComputePrincipalAxes(const std::vector<Vec3f>& points,
                                   const std::vector<uint32_t>* subset = nullptr);

// Distance-weighted PCA about a given centre, as in SHOT's local reference
// frame (Tombari et al., ECCV 2010): each point weighs (radius - |p - centre|),
// so the nearest surface dominates and points entering or leaving the support
// at its rim change the axes only slightly, which makes the axes repeatable
// under resampling and small deformations. `centroid` is set to `center`.
PrincipalAxes ComputeWeightedPrincipalAxes(const std::vector<Vec3f>& points,
                                           const std::vector<uint32_t>& subset,
                                           const Vec3d& center,
                                           double radius);

// Eigen-decomposition of a symmetric 3x3 matrix by cyclic Jacobi rotations
// (exact to round-off, robust for repeated eigenvalues). Eigenvalues in
// decreasing order, eigenvectors as unit columns in the same order.
void SymmetricEigen3(const std::array<std::array<double, 3>, 3>& matrix,
                     std::array<double, 3>* eigenvalues,
                     std::array<Vec3d, 3>* eigenvectors);

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_GEOMETRY_PRINCIPAL_AXES_H_
