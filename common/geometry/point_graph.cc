#include "common/geometry/point_graph.h"

#include <algorithm>
#include <cmath>
#include <flann/flann.hpp>

#include "absl/strings/str_cat.h"

namespace meshseek {

double PointGraph::MeanEdgeLength(std::size_t i) const {
  const auto nbrs = NeighborsOf(i);
  if (nbrs.empty()) return 0;
  double sum = 0;
  for (const uint32_t j : nbrs) sum += Distance(Vec3d(positions[i]), Vec3d(positions[j]));
  return sum / nbrs.size();
}

absl::Status ValidatePointGraph(const PointGraph& graph) {
  const std::size_t n = graph.positions.size();
  if (graph.offsets.size() != n + 1) {
    return absl::InvalidArgumentError(absl::StrCat(
        "point graph: ", graph.offsets.size(), " offsets for ", n, " points (need ", n + 1, ")"));
  }
  if (graph.boundary.size() != n) {
    return absl::InvalidArgumentError(absl::StrCat(
        "point graph: ", graph.boundary.size(), " boundary flags for ", n, " points"));
  }
  if (graph.offsets[0] != 0 || graph.offsets[n] != graph.neighbors.size()) {
    return absl::InvalidArgumentError(
        absl::StrCat("point graph: offsets must run from 0 to the neighbour count ",
                     graph.neighbors.size(), ", got ", graph.offsets[0], " to ", graph.offsets[n]));
  }
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3f& p = graph.positions[i];
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
      return absl::InvalidArgumentError(absl::StrCat("point graph: point ", i, " is not finite"));
    }
    // Each offset is checked against the neighbour count as well as against
    // the previous one: offsets[n] bounds the last offset only, and a later
    // decrease would come too late to stop the reads below.
    if (graph.offsets[i + 1] < graph.offsets[i] ||
        graph.offsets[i + 1] > graph.neighbors.size()) {
      return absl::InvalidArgumentError(
          absl::StrCat("point graph: offsets decrease at point ", i, " (", graph.offsets[i], " to ",
                       graph.offsets[i + 1], ", ", graph.neighbors.size(), " neighbours)"));
    }
    for (uint32_t k = graph.offsets[i]; k < graph.offsets[i + 1]; ++k) {
      if (graph.neighbors[k] >= n || graph.neighbors[k] == i) {
        return absl::InvalidArgumentError(absl::StrCat(
            "point graph: point ", i, " has neighbour ", graph.neighbors[k], " (", n, " points)"));
      }
    }
  }
  return absl::OkStatus();
}

PointGraph MakePointGraph(std::vector<Vec3f> positions,
                          const std::vector<std::pair<uint32_t, uint32_t>>& edges) {
  PointGraph graph;
  const std::size_t n = positions.size();
  graph.positions = std::move(positions);
  graph.boundary.assign(n, 0);
  std::vector<uint32_t> degree(n + 1, 0);
  for (const auto& [a, b] : edges) {
    if (a == b) continue;
    ++degree[a];
    ++degree[b];
  }
  graph.offsets.assign(n + 1, 0);
  for (std::size_t i = 0; i < n; ++i) graph.offsets[i + 1] = graph.offsets[i] + degree[i];
  graph.neighbors.resize(graph.offsets[n]);
  std::vector<uint32_t> fill(graph.offsets.begin(), graph.offsets.end() - 1);
  for (const auto& [a, b] : edges) {
    if (a == b) continue;
    graph.neighbors[fill[a]++] = b;
    graph.neighbors[fill[b]++] = a;
  }
  // Sort and deduplicate each list, compacting in place.
  uint32_t out = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const auto begin = graph.neighbors.begin() + graph.offsets[i];
    const auto end = graph.neighbors.begin() + graph.offsets[i + 1];
    std::sort(begin, end);
    const auto last = std::unique(begin, end);
    graph.offsets[i] = out;
    for (auto it = begin; it != last; ++it) graph.neighbors[out++] = *it;
  }
  graph.offsets[n] = out;
  graph.neighbors.resize(out);
  return graph;
}

absl::StatusOr<PointGraph> SymmetricKnnGraph(const std::vector<Vec3f>& points, int k) {
  if (k < 1) return absl::InvalidArgumentError(absl::StrCat("k must be >= 1, got ", k));
  if (points.size() <= static_cast<std::size_t>(k)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "a ", k, "-nearest-neighbour graph needs more than ", k, " points, got ", points.size()));
  }
  const std::size_t n = points.size();
  // FLANN wants a mutable row-major float matrix; Vec3f is three packed floats.
  std::vector<float> coords(3 * n);
  for (std::size_t i = 0; i < n; ++i) {
    coords[3 * i] = points[i].x;
    coords[3 * i + 1] = points[i].y;
    coords[3 * i + 2] = points[i].z;
  }
  const flann::Matrix<float> data(coords.data(), n, 3);
  flann::Index<flann::L2_Simple<float>> index(data, flann::KDTreeSingleIndexParams(10));
  index.buildIndex();
  // k + 1: each point finds itself first (or a duplicate of itself).
  std::vector<int> indices((k + 1) * n);
  std::vector<float> dists((k + 1) * n);
  flann::Matrix<int> index_matrix(indices.data(), n, k + 1);
  flann::Matrix<float> dist_matrix(dists.data(), n, k + 1);
  flann::SearchParams params(flann::FLANN_CHECKS_UNLIMITED);
  params.cores = 1;
  params.sorted = true;
  index.knnSearch(data, index_matrix, dist_matrix, k + 1, params);
  std::vector<std::pair<uint32_t, uint32_t>> edges;
  edges.reserve(k * n);
  for (std::size_t i = 0; i < n; ++i) {
    int added = 0;
    for (int c = 0; c <= k && added < k; ++c) {
      const int j = index_matrix[i][c];
      if (j < 0 || static_cast<std::size_t>(j) == i) continue;
      edges.emplace_back(static_cast<uint32_t>(i), static_cast<uint32_t>(j));
      ++added;
    }
  }
  return MakePointGraph(points, edges);
}

}  // namespace meshseek
