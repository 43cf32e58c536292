#include "common/geometry/surface_sampler.h"

#include <cmath>

#include "absl/strings/str_cat.h"
#include "common/geometry/sobol.h"

namespace meshseek {

absl::StatusOr<SurfacePoints> SampleSurface(const TriangleMesh& mesh, int64_t count) {
  if (count <= 0) {
    return absl::InvalidArgumentError(absl::StrCat("sample count must be positive, got ", count));
  }
  const std::size_t nt = mesh.triangles.size();
  std::vector<double> areas(nt);
  double total = 0;
  std::size_t last_positive = nt;
  for (std::size_t t = 0; t < nt; ++t) {
    areas[t] = TriangleArea(mesh, t);
    if (areas[t] > 0) {
      total += areas[t];
      last_positive = t;
    }
  }
  if (!(total > 0) || !std::isfinite(total)) {
    return absl::InvalidArgumentError(
        absl::StrCat("cannot sample a surface of area ", total, " (", nt, " triangles)"));
  }
  // Points per triangle by error diffusion.
  const double per_area = static_cast<double>(count) / total;
  std::vector<int64_t> quota(nt, 0);
  double carry = 0;
  int64_t assigned = 0;
  for (std::size_t t = 0; t < nt; ++t) {
    if (!(areas[t] > 0)) continue;
    const double exact = areas[t] * per_area + carry;
    int64_t q = static_cast<int64_t>(std::floor(exact));
    q = std::min(q, count - assigned);  // never overshoot on round-off
    carry = exact - static_cast<double>(q);
    quota[t] = q;
    assigned += q;
  }
  quota[last_positive] += count - assigned;  // top up the round-off shortfall

  SurfacePoints points;
  points.positions.reserve(count);
  points.normals.reserve(count);
  points.faces.reserve(count);
  Sobol2D sobol;
  for (std::size_t t = 0; t < nt; ++t) {
    if (quota[t] == 0) continue;
    const auto c = mesh.Corners(t);
    const Vec3f normal(TriangleNormal(mesh, t));
    for (int64_t k = 0; k < quota[t]; ++k) {
      const auto u = sobol.Next();
      const double r = std::sqrt(u[0]);
      const Vec3d p = c[0] * (1 - r) + c[1] * (r * (1 - u[1])) + c[2] * (r * u[1]);
      points.positions.emplace_back(p);
      points.normals.push_back(normal);
      points.faces.push_back(static_cast<uint32_t>(t));
    }
  }
  return points;
}

}  // namespace meshseek
