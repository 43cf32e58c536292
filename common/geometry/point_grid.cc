#include "common/geometry/point_grid.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace meshseek {
namespace {
constexpr int64_t kCoordBits = 21;  // 2^21 cells per axis, far more than any model needs
constexpr int64_t kCoordMax = (int64_t{1} << kCoordBits) - 1;
}  // namespace

PointGrid::PointGrid(const std::vector<Vec3f>& points, float cell_size)
    : points_(points), cell_size_(cell_size) {
  if (points.empty()) return;
  origin_ = points[0];
  for (const Vec3f& p : points) {
    origin_ = {std::min(origin_.x, p.x), std::min(origin_.y, p.y), std::min(origin_.z, p.z)};
  }
  std::vector<uint64_t> keys(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    keys[i] = Key(CellCoord(points[i].x, 0), CellCoord(points[i].y, 1), CellCoord(points[i].z, 2));
  }
  sorted_.resize(points.size());
  std::iota(sorted_.begin(), sorted_.end(), 0u);
  std::stable_sort(
      sorted_.begin(), sorted_.end(), [&](uint32_t a, uint32_t b) { return keys[a] < keys[b]; });
  for (uint32_t i = 0; i < sorted_.size(); ++i) {
    const uint64_t key = keys[sorted_[i]];
    if (cell_keys_.empty() || cell_keys_.back() != key) {
      cell_keys_.push_back(key);
      cell_starts_.push_back(i);
    }
  }
  cell_starts_.push_back(static_cast<uint32_t>(sorted_.size()));
}

int64_t PointGrid::CellCoord(float value, int axis) const {
  const double c = std::floor((static_cast<double>(value) - origin_[axis]) / cell_size_);
  return static_cast<int64_t>(std::clamp(c, 0.0, static_cast<double>(kCoordMax)));
}

uint64_t PointGrid::Key(int64_t ix, int64_t iy, int64_t iz) const {
  return (static_cast<uint64_t>(ix) << (2 * kCoordBits)) |
         (static_cast<uint64_t>(iy) << kCoordBits) | static_cast<uint64_t>(iz);
}

void PointGrid::RadiusQuery(const Vec3f& center, float radius, std::vector<uint32_t>* out) const {
  if (cell_keys_.empty()) return;
  const float r2 = radius * radius;
  int64_t lo[3], hi[3];
  for (int a = 0; a < 3; ++a) {
    lo[a] = CellCoord(center[a] - radius, a);
    hi[a] = CellCoord(center[a] + radius, a);
  }
  for (int64_t ix = lo[0]; ix <= hi[0]; ++ix) {
    for (int64_t iy = lo[1]; iy <= hi[1]; ++iy) {
      // Cells along z with fixed (x, y) are contiguous in key order.
      const uint64_t first = Key(ix, iy, lo[2]), last = Key(ix, iy, hi[2]);
      auto it = std::lower_bound(cell_keys_.begin(), cell_keys_.end(), first);
      for (; it != cell_keys_.end() && *it <= last; ++it) {
        const std::size_t c = static_cast<std::size_t>(it - cell_keys_.begin());
        for (uint32_t k = cell_starts_[c]; k < cell_starts_[c + 1]; ++k) {
          const uint32_t idx = sorted_[k];
          if (SquaredDistance(points_[idx], center) <= r2) out->push_back(idx);
        }
      }
    }
  }
}

}  // namespace meshseek
