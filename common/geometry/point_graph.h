// Undirected graphs over points, the domain of the LD-SIFT scale space
// (docs/design.md 2.5): a mesh's own vertex connectivity for LD-SIFT, a symmetrised
// k-nearest-neighbour graph over surface samples for RLD-SIFT.
#ifndef MESHSEEK_COMMON_GEOMETRY_POINT_GRAPH_H_
#define MESHSEEK_COMMON_GEOMETRY_POINT_GRAPH_H_

#include <cstdint>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/types/span.h"
#include "common/geometry/mesh.h"

namespace meshseek {

// Compressed adjacency: the neighbours of vertex i are
// neighbors[offsets[i] .. offsets[i + 1]), sorted, without i and without
// repeats.
struct PointGraph {
  std::vector<Vec3f> positions;
  std::vector<uint32_t> offsets;  // size() + 1 entries
  std::vector<uint32_t> neighbors;
  // 1 for vertices on an open boundary of a mesh (an edge used by one face
  // only); scale-space detection skips them. All 0 for point-cloud graphs.
  std::vector<uint8_t> boundary;

  std::size_t size() const { return positions.size(); }
  absl::Span<const uint32_t> NeighborsOf(std::size_t i) const {
    return absl::MakeConstSpan(neighbors.data() + offsets[i], offsets[i + 1] - offsets[i]);
  }
  // Mean length of i's edges, 0 for an isolated vertex.
  double MeanEdgeLength(std::size_t i) const;
};

// Builds the adjacency from undirected edge lists (pairs may repeat and come
// in either order; self-loops are dropped).
PointGraph MakePointGraph(std::vector<Vec3f> positions,
                          const std::vector<std::pair<uint32_t, uint32_t>>& edges);

// Checks what a graph from outside (the resample service) must satisfy:
// offsets of size n + 1 starting at 0, non-decreasing, ending at the
// neighbour count; neighbours in range, not the point itself; finite
// positions; boundary of size n. The message names the first
// offending point.
absl::Status ValidatePointGraph(const PointGraph& graph);

// The symmetrised k-nearest-neighbour graph (Euclidean): i and j are joined
// when either is among the other's k nearest (exact search, FLANN kd-tree;
// ties by index). Needs more than k points.
absl::StatusOr<PointGraph> SymmetricKnnGraph(const std::vector<Vec3f>& points, int k);

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_GEOMETRY_POINT_GRAPH_H_
