#include "common/features/scale_space.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"

namespace meshseek {

absl::Status ScaleSpaceOptions::Validate() const {
  if (levels < 2 || levels > 200) {
    return absl::InvalidArgumentError(
        absl::StrCat("scale-space levels L must be in [2, 200], got ", levels));
  }
  if (!(scale_factor > 0)) {
    return absl::InvalidArgumentError(
        absl::StrCat("scale factor C must be positive, got ", scale_factor));
  }
  return absl::OkStatus();
}

float MedianScale(const std::vector<InterestPoint>& points) {
  if (points.empty()) return 0;
  std::vector<float> scales;
  scales.reserve(points.size());
  for (const InterestPoint& p : points) scales.push_back(p.scale);
  std::nth_element(scales.begin(), scales.begin() + scales.size() / 2, scales.end());
  return scales[scales.size() / 2];
}

std::vector<InterestPoint> DetectInterestPoints(const PointGraph& graph,
                                                const ScaleSpaceOptions& options) {
  const std::size_t n = graph.size();
  const int levels = options.levels;
  // dog[(k - 1) * n + i] = normalised D_k(i), k = 1..L.
  std::vector<float> dog(static_cast<std::size_t>(levels) * n);
  std::vector<Vec3d> current(n), next(n);
  for (std::size_t i = 0; i < n; ++i) current[i] = Vec3d(graph.positions[i]);
  for (int k = 1; k <= levels; ++k) {
    double total = 0;
    float* d = dog.data() + static_cast<std::size_t>(k - 1) * n;
    for (std::size_t i = 0; i < n; ++i) {
      Vec3d sum = current[i];
      const auto nbrs = graph.NeighborsOf(i);
      for (const uint32_t j : nbrs) sum += current[j];
      next[i] = sum / static_cast<double>(1 + nbrs.size());
      const double disp = SquaredDistance(current[i], next[i]);
      d[i] = static_cast<float>(disp);
      total += disp;
    }
    if (total > 0) {
      const double inv = 1.0 / total;
      for (std::size_t i = 0; i < n; ++i) d[i] = static_cast<float>(d[i] * inv);
    }
    current.swap(next);
  }

  auto at = [&](int k, std::size_t i) { return dog[static_cast<std::size_t>(k - 1) * n + i]; };
  std::vector<InterestPoint> points;
  for (std::size_t i = 0; i < n; ++i) {
    if (graph.boundary[i]) continue;
    const auto nbrs = graph.NeighborsOf(i);
    if (nbrs.empty()) continue;
    int best = 1;
    for (int k = 2; k <= levels; ++k) {
      if (at(k, i) > at(best, i)) best = k;
    }
    if (best >= levels) continue;
    const float value = at(best, i);
    if (!(value > 0)) continue;
    bool maximum = true;
    for (int k = std::max(1, best - 1); k <= best + 1 && maximum; ++k) {
      for (const uint32_t j : nbrs) {
        if (at(k, j) > value) {
          maximum = false;
          break;
        }
      }
    }
    if (!maximum) continue;
    const double scale = options.scale_factor * graph.MeanEdgeLength(i) * std::sqrt(best);
    points.push_back({static_cast<uint32_t>(i), best, static_cast<float>(scale), value});
  }
  return points;
}

}  // namespace meshseek
