// Exact nearest-centroid search by squared Euclidean distance.
//
// This is the one implementation behind both the assignment step of k-means
// (kmeans.h) and bag-of-features encoding (codebook.h), so a codebook encodes
// descriptors exactly the way its training assigned them.
//
// Method. ||x - c||^2 = ||x||^2 - 2 x.c + ||c||^2, and the argmin over c needs
// only ||c||^2 - 2 x.c, so the search is a points-by-centroids matrix product
// with a running minimum (as in Faiss's exhaustive L2 search). The product is a
// register-blocked kernel: centroids are packed in panels of 16,
// dimension-major, and for each dimension 8 point values are each multiplied by
// the 16 contiguous centroid values of the panel. It is portable C++ on
// GCC/Clang generic vector types (nearest_centroid.cc says why not plain
// loops), compiled for baseline x86-64 (SSE2) and, chosen at run time
// (cpu_features.h), for AVX2 and AVX-512. Centroids are visited in cache-sized
// tiles so that the packed tile stays in L2 while a block of points is
// searched against it. On one core of the development machines:
// bench/results/codebook.txt.
//
// Determinism. Vectorising across centroids, not across dimensions, means every
// dot product x.c is summed in the order d = 0, 1, ..., dim - 1 whatever the
// blocking, the vector width or the thread count; ties go to the lowest centroid
// index. Points are split into fixed blocks that do not depend on the thread
// count. Results are therefore bit-identical for any num_threads and on any
// machine, whichever variant runs (a test pins it). The module is compiled with
// -ffp-contract=off so that no variant fuses a multiply-add on hardware with
// FMA, which would change the rounding.
//
// Accuracy. The expansion loses relative precision when ||x - c||^2 is much
// smaller than ||x||^2. For SIFT descriptors (norm about 512, squared distances
// to the nearest word 1e4..1e5) the float error is a few ulps of 2.6e5, well
// under 1, far below the gaps that decide an assignment. Returned distances are
// clamped at 0.
#ifndef MESHSEEK_COMMON_BOF_NEAREST_CENTROID_H_
#define MESHSEEK_COMMON_BOF_NEAREST_CENTROID_H_

#include <cstddef>
#include <cstdint>
#include <vector>

#include "common/base/cpu_features.h"

namespace meshseek {

// Immutable once built; Search() may be called from several threads at once.
class NearestCentroidIndex {
 public:
  /// An index over no centroids; Search() must not be called on it.
  NearestCentroidIndex() = default;

  /// Copies and packs `num_centroids` x `dim` row-major centroids. The caller
  /// has checked the input (kmeans.cc and codebook.cc do): num_centroids >= 1
  /// and < 2^32, dim >= 1, all values finite. `simd` selects the kernel
  /// variant (capped at what the CPU has); only tests and benchmarks that
  /// compare the variants pass it, the results being the same.
  NearestCentroidIndex(const float* centroids,
                       std::size_t num_centroids,
                       std::size_t dim,
                       SimdLevel simd = DetectedSimdLevel());

  std::size_t num_centroids() const { return num_centroids_; }
  std::size_t dim() const { return dim_; }
  /// The kernel variant this index runs.
  SimdLevel simd() const { return simd_; }

  /// For each of the `n` row-major points (n x dim), writes the index of the
  /// nearest centroid to labels[i] and, when `squared_distances` is not null,
  /// the squared Euclidean distance to it. Runs on up to `num_threads` threads
  /// (<= 0: all cores); the result does not depend on the thread count.
  void Search(const float* points,
              std::size_t n,
              int num_threads,
              uint32_t* labels,
              float* squared_distances) const;

  /// The same for uint8 points (quantised SIFT), converted to float in small
  /// blocks on the fly so that no float copy of the whole set is made.
  void Search(const uint8_t* points,
              std::size_t n,
              int num_threads,
              uint32_t* labels,
              float* squared_distances) const;

  /// The `k` nearest centroids of each of the `n` row-major float points, on
  /// the calling thread: labels and scores are n x k, row i listing point i's
  /// neighbours by increasing score, ties by increasing index (k is clamped to
  /// num_centroids(); callers pass k <= num_centroids()). The score is
  /// ||c||^2 - 2 x.c, i.e. the squared distance less ||x||^2, computed exactly
  /// as Search() computes it, so that scores of one point against different
  /// indexes (approximate_nearest_centroid.h) compare as Search() would, and
  /// with k = 1 the label is Search()'s.
  void SearchTopK(const float* points,
                  std::size_t n,
                  std::size_t k,
                  uint32_t* labels,
                  float* scores) const;

 private:
  template <typename T>
  void SearchImpl(const T* points,
                  std::size_t n,
                  int num_threads,
                  uint32_t* labels,
                  float* squared_distances) const;

  std::size_t num_centroids_ = 0;
  std::size_t dim_ = 0;
  SimdLevel simd_ = SimdLevel::kSse2;
  // Panels of 16 centroids, each dim x 16 floats (dimension-major); the last
  // panel is padded with zero centroids whose norm is +inf so they never win.
  std::vector<float> packed_;
  // ||c||^2 per padded centroid.
  std::vector<float> norms_;
};

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_BOF_NEAREST_CENTROID_H_
