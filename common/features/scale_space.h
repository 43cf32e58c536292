// LD-SIFT's interest-point detector on a point graph (Darom & Keller 2012, as
// their public code does it; docs/design.md 2.5), used by LD-SIFT on the mesh's own
// vertex graph and by RLD-SIFT on a k-nearest-neighbour graph of surface
// samples. Written once for both.
//
// Scale space: positions smoothed repeatedly with uniform weights over the
// vertex and its neighbours,
//   v^(k)_i = (v^(k-1)_i + sum_{j ~ i} v^(k-1)_j) / (1 + deg_i),  k = 1..L,
// and the difference of Gaussians of level k is the squared displacement
//   D_k(i) = |v^(k-1)_i - v^(k)_i|^2,
// normalised per level by its sum over all vertices (so levels compare).
// Vertex i is an interest point at level l (1 <= l < L) if l is where D(i)
// peaks over all levels and D_l(i) >= D_{l'}(j) for every neighbour j and
// l' in {l-1, l, l+1}. No threshold; open-boundary vertices are skipped. Its
// feature scale is s_i = C * d_i * sqrt(l), d_i the mean length of i's edges on
// the unsmoothed graph. The paper's "DoG level 0" is l = 1.
// Cost: O(L * (vertices + edges)) time, O(L * vertices) memory.
#ifndef MESHSEEK_COMMON_FEATURES_SCALE_SPACE_H_
#define MESHSEEK_COMMON_FEATURES_SCALE_SPACE_H_

#include <cstdint>
#include <vector>

#include "absl/status/status.h"
#include "common/geometry/point_graph.h"

namespace meshseek {

struct ScaleSpaceOptions {
  /// L, the number of smoothing levels (the LD-SIFT code uses 20, no octaves).
  int levels = 20;
  /// C in s = C * d * sqrt(l) (LD-SIFT: 5).
  double scale_factor = 5.0;

  absl::Status Validate() const;
};

struct InterestPoint {
  uint32_t vertex;  // index into the graph
  int level;        // l, 1-based (the paper's DoG level l - 1)
  float scale;      // s = C * d * sqrt(l), model units
  float response;   // normalised D_l at the vertex
};

// Interest points in increasing vertex order. The graph's positions are not
// modified.
std::vector<InterestPoint> DetectInterestPoints(const PointGraph& graph,
                                                const ScaleSpaceOptions& options);

// The median feature scale of `points` (a good cell size for a grid of
// support points); 0 if there are none.
float MedianScale(const std::vector<InterestPoint>& points);

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_FEATURES_SCALE_SPACE_H_
