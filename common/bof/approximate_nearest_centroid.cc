#include "common/bof/approximate_nearest_centroid.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "common/base/logging.h"
#include "common/base/parallel.h"
#include "common/bof/kmeans.h"

namespace meshseek {
namespace {

// Points per ParallelFor item. Fixed, so results never depend on the thread
// count; large enough that each probed group gets a batch of points
// (4,096 x 8 probes / 400 groups = 82 at V = 20,000) for the blocked kernel.
constexpr std::size_t kPointsPerBlock = 4096;
// Lloyd iterations of the grouping k-means: the groups only need to be
// compact, not converged (each extra iteration at V = 20,000 costs ~40 ms).
constexpr int kGroupingIterations = 10;
// Fixed: the grouping must be a function of the centroids alone.
constexpr uint64_t kGroupingSeed = 0x6d657368;  // "mesh"

}  // namespace

ApproximateSearchParams ApproximateSearchParams::Resolve(int groups,
                                                         int probes,
                                                         std::size_t num_centroids) {
  const double v = static_cast<double>(std::max<std::size_t>(1, num_centroids));
  ApproximateSearchParams p;
  p.probes = std::max(1, probes);
  const double automatic = std::round(std::sqrt(static_cast<double>(p.probes) * v));
  p.groups = static_cast<int>(std::clamp<double>(groups > 0 ? groups : automatic, 1.0, v));
  p.probes = std::min(p.probes, p.groups);
  return p;
}

ApproximateNearestCentroidIndex::ApproximateNearestCentroidIndex(
    const float* centroids,
    std::size_t num_centroids,
    std::size_t dim,
    const ApproximateSearchParams& params,
    int num_threads)
    : num_centroids_(num_centroids), dim_(dim), params_(params) {
  const std::size_t g = static_cast<std::size_t>(params.groups);
  KMeansOptions grouping;
  grouping.num_centroids = params.groups;
  grouping.assignment = KMeansOptions::Assignment::kExact;
  grouping.max_iterations = kGroupingIterations;
  grouping.seed = kGroupingSeed;
  grouping.num_threads = num_threads;
  grouping.min_points_per_centroid = 1;  // V / G is ~50 at the defaults: no warning
  absl::StatusOr<std::vector<float>> centres =
      internal::TrainKMeansQuietly(centroids, num_centroids, dim, grouping, nullptr);
  // Cannot fail: the caller checked the centroids and G <= V (Resolve).
  if (!centres.ok()) MESHSEEK_LOG(FATAL) << "grouping centroids: " << centres.status();
  std::vector<uint32_t> group_of(num_centroids);
  NearestCentroidIndex(centres->data(), g, dim)
      .Search(centroids, num_centroids, num_threads, group_of.data(), nullptr);
  groups_.resize(g);
  for (std::size_t c = 0; c < num_centroids; ++c) {
    groups_[group_of[c]].members.push_back(static_cast<uint32_t>(c));
  }
  // A group can end up without centroids (its centre lost them all in the
  // final assignment); drop it, so that every probe finds candidates.
  std::vector<float> kept;
  std::size_t num_kept = 0;
  for (std::size_t i = 0; i < g; ++i) {
    if (groups_[i].members.empty()) continue;
    kept.insert(kept.end(), centres->begin() + i * dim, centres->begin() + (i + 1) * dim);
    if (i != num_kept) groups_[num_kept] = std::move(groups_[i]);
    ++num_kept;
  }
  groups_.resize(num_kept);
  coarse_ = NearestCentroidIndex(kept.data(), num_kept, dim);
  probes_ = std::min<std::size_t>(static_cast<std::size_t>(params.probes), num_kept);
  ParallelFor(g, num_threads, [&](std::size_t i) {
    Group& group = groups_[i];
    if (group.members.empty()) return;
    std::vector<float> rows(group.members.size() * dim);
    for (std::size_t j = 0; j < group.members.size(); ++j) {
      std::copy_n(centroids + group.members[j] * dim, dim, &rows[j * dim]);
    }
    group.index = NearestCentroidIndex(rows.data(), group.members.size(), dim);
  });
}

void ApproximateNearestCentroidIndex::Search(const float* points,
                                             std::size_t n,
                                             int num_threads,
                                             uint32_t* labels,
                                             float* squared_distances) const {
  SearchImpl(points, n, num_threads, labels, squared_distances);
}

void ApproximateNearestCentroidIndex::Search(const uint8_t* points,
                                             std::size_t n,
                                             int num_threads,
                                             uint32_t* labels,
                                             float* squared_distances) const {
  SearchImpl(points, n, num_threads, labels, squared_distances);
}

template <typename T>
void ApproximateNearestCentroidIndex::SearchImpl(const T* points,
                                                 std::size_t n,
                                                 int num_threads,
                                                 uint32_t* labels,
                                                 float* squared_distances) const {
  const std::size_t dim = dim_;
  const std::size_t probes = probes_;
  const std::size_t num_groups = groups_.size();
  const std::size_t num_blocks = (n + kPointsPerBlock - 1) / kPointsPerBlock;
  ParallelFor(num_blocks, num_threads, [&](std::size_t block) {
    const std::size_t begin = block * kPointsPerBlock;
    const std::size_t count = std::min(kPointsPerBlock, n - begin);
    std::vector<float> x(count * dim);
    for (std::size_t i = 0; i < count * dim; ++i) {
      x[i] = static_cast<float>(points[begin * dim + i]);
    }
    // Level 1: the probed groups of every point.
    std::vector<uint32_t> probe(count * probes);
    std::vector<float> probe_score(count * probes);
    coarse_.SearchTopK(x.data(), count, probes, probe.data(), probe_score.data());

    // Bucket the points by probed group (counting sort: each bucket lists its
    // points in increasing order).
    std::vector<std::size_t> offsets(num_groups + 1, 0);
    for (uint32_t g : probe) ++offsets[g + 1];
    for (std::size_t g = 0; g < num_groups; ++g) offsets[g + 1] += offsets[g];
    std::vector<uint32_t> bucket(count * probes);
    {
      std::vector<std::size_t> next(offsets.begin(), offsets.end() - 1);
      for (std::size_t i = 0; i < count * probes; ++i) {
        bucket[next[probe[i]]++] = static_cast<uint32_t>(i / probes);
      }
    }

    // Level 2: each group against its batch of points. The minimum over
    // groups, with ties to the lowest global index, does not depend on the
    // order the groups are visited in.
    std::vector<float> best(count, std::numeric_limits<float>::infinity());
    std::vector<uint32_t> best_label(count, std::numeric_limits<uint32_t>::max());
    std::vector<float> batch;
    std::vector<uint32_t> local(kPointsPerBlock);
    std::vector<float> score(kPointsPerBlock);
    for (std::size_t g = 0; g < num_groups; ++g) {
      const std::size_t m = offsets[g + 1] - offsets[g];
      if (m == 0) continue;
      batch.resize(m * dim);
      for (std::size_t j = 0; j < m; ++j) {
        std::copy_n(&x[bucket[offsets[g] + j] * dim], dim, &batch[j * dim]);
      }
      groups_[g].index.SearchTopK(batch.data(), m, 1, local.data(), score.data());
      for (std::size_t j = 0; j < m; ++j) {
        const uint32_t i = bucket[offsets[g] + j];
        const uint32_t label = groups_[g].members[local[j]];
        if (score[j] < best[i] || (score[j] == best[i] && label < best_label[i])) {
          best[i] = score[j];
          best_label[i] = label;
        }
      }
    }

    for (std::size_t i = 0; i < count; ++i) {
      labels[begin + i] = best_label[i];
      if (squared_distances == nullptr) continue;
      // As NearestCentroidIndex::Search: ||x||^2 in double, plus the score.
      double norm = 0.0;
      for (std::size_t d = 0; d < dim; ++d) {
        norm += static_cast<double>(x[i * dim + d]) * x[i * dim + d];
      }
      squared_distances[begin + i] = std::max(0.0f, static_cast<float>(norm) + best[i]);
    }
  });
}

}  // namespace meshseek
