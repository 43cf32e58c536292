// Approximate nearest-centroid search for large vocabularies (V = 10,000 and
// more), used by k-means training (kmeans.h) and by encoding (codebook.h) when
// KMeansOptions::assignment selects it.
//
// Why. Exact search costs V x dim multiply-adds per descriptor: at V = 20,000,
// one Lloyd iteration over 1,000,000 SIFT descriptors is 5.1 TFLOP, about 70 s
// on the two cores of the development machine, and encoding one model of 2,500
// descriptors takes 0.35 s. The budgets (training in 5 minutes,
// 1,000 models encoded in 60 s) need a search that touches a few percent of the
// centroids.
//
// Method: a two-level inverted file over the centroids (an IVF whose "database"
// is the vocabulary itself). The V centroids are clustered by exact k-means
// into G groups; a point is compared with the G group centres, then exactly
// with every centroid of its `probes` nearest groups, and takes the nearest of
// those. Cost per point: G + probes * V / G distances, smallest at
// G = sqrt(probes * V) (the default): 800 instead of 20,000 at V = 20,000,
// probes = 8. Both levels run on NearestCentroidIndex's register-blocked exact
// kernel (points are bucketed by probed group, so each group is searched for a
// batch of points at once), so the distances computed are bit-identical to the
// exact search's: when the exact nearest centroid lies in a probed group, the
// answer is the exact one, tie rule included. Faiss 1.7.3 as Debian builds it
// (no SIMD) was measured against this (bench/results/codebook.txt): its
// IndexIVFFlat with the same lists and probes is 5x slower at the same
// agreement, and IndexHNSWFlat takes 17 s to build over 20,000 centroids (once
// per Lloyd iteration) and agrees less (0.94 at efSearch 128).
//
// Determinism. The grouping is a function of the centroids, G and probes only
// (its k-means has a fixed seed), so a codebook rebuilt from its serialised
// centroids searches identically. Points are processed in fixed blocks and
// each point's answer depends only on its own distances, so results are
// bit-identical for any thread count.
#ifndef MESHSEEK_COMMON_BOF_APPROXIMATE_NEAREST_CENTROID_H_
#define MESHSEEK_COMMON_BOF_APPROXIMATE_NEAREST_CENTROID_H_

#include <cstddef>
#include <cstdint>
#include <vector>

#include "common/bof/nearest_centroid.h"

namespace meshseek {

/// The two knobs of the approximate search, as resolved (no "auto" values).
struct ApproximateSearchParams {
  /// Number of groups G the centroids are clustered into; 1..V.
  int groups = 1;
  /// Groups searched per point; 1..groups.
  int probes = 1;

  /// G = round(sqrt(probes * V)) clamped to [1, V] when `groups` <= 0, and
  /// probes clamped to [1, G]: the parameters actually used for V centroids.
  static ApproximateSearchParams Resolve(int groups, int probes, std::size_t num_centroids);

  bool operator==(const ApproximateSearchParams& o) const {
    return groups == o.groups && probes == o.probes;
  }
};

// Immutable once built; Search() may be called from several threads at once.
class ApproximateNearestCentroidIndex {
 public:
  /// Groups `num_centroids` x `dim` row-major centroids (checked by the caller
  /// as for NearestCentroidIndex) with `params` (already resolved for
  /// num_centroids). The grouping k-means runs on up to `num_threads` threads;
  /// the result does not depend on it.
  ApproximateNearestCentroidIndex(const float* centroids,
                                  std::size_t num_centroids,
                                  std::size_t dim,
                                  const ApproximateSearchParams& params,
                                  int num_threads);

  std::size_t num_centroids() const { return num_centroids_; }
  std::size_t dim() const { return dim_; }
  const ApproximateSearchParams& params() const { return params_; }

  /// As NearestCentroidIndex::Search, but the label is the nearest centroid
  /// among the probed groups' (ties to the lowest index), and the distance is
  /// to that centroid.
  void Search(const float* points,
              std::size_t n,
              int num_threads,
              uint32_t* labels,
              float* squared_distances) const;
  void Search(const uint8_t* points,
              std::size_t n,
              int num_threads,
              uint32_t* labels,
              float* squared_distances) const;

 private:
  template <typename T>
  void SearchImpl(const T* points,
                  std::size_t n,
                  int num_threads,
                  uint32_t* labels,
                  float* squared_distances) const;

  std::size_t num_centroids_ = 0;
  std::size_t dim_ = 0;
  ApproximateSearchParams params_;
  // The centres of the groups that have centroids (at most G).
  NearestCentroidIndex coarse_;
  // min(probes, number of groups kept).
  std::size_t probes_ = 1;
  // Per group: its centroids (global indices, increasing) and an exact index
  // over them.
  struct Group {
    std::vector<uint32_t> members;
    NearestCentroidIndex index;
  };
  std::vector<Group> groups_;
};

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_BOF_APPROXIMATE_NEAREST_CENTROID_H_
