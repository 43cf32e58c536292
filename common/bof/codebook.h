// A visual vocabulary for bag-of-features (DESIGN.md 2.7): V centroids
// ("visual words") in descriptor space, learnt by k-means over local features
// of the collection's own models, and the encoder that turns one model's local
// descriptors into a normalised histogram of nearest words.
//
// Encoding uses exact nearest-centroid search, the same implementation that
// assigned points during training (nearest_centroid.h), at about 15 ms for
// 2,048 descriptors against V = 1,000 on one core. That is fast enough that the
// approximate kd-tree search DESIGN.md allows is not needed, and exactness
// keeps encoding identical on every machine and thread count.
//
// A Codebook is immutable once made; its const methods may be called from
// several threads at once.
//
// Serialised form (for the codebook service to persist), little-endian:
//   "MSCB" | uint32 version (1) | uint64 V | uint64 dim | V * dim float32,
//   row-major | uint64 FNV-1a 64 hash of every preceding byte.
// Deserialize checks every part and rejects anything else.
#ifndef MESHSEEK_COMMON_BOF_CODEBOOK_H_
#define MESHSEEK_COMMON_BOF_CODEBOOK_H_

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "common/bof/kmeans.h"
#include "common/bof/nearest_centroid.h"

namespace meshseek {

class Codebook {
 public:
  /// Learns a codebook of options.num_centroids words by k-means (kmeans.h)
  /// over `count` row-major uint8 descriptors of `dim` values each (a sample
  /// of the collection's local features; kSiftDimension, 128, for SIFT).
  /// Errors are TrainKMeans's.
  static absl::StatusOr<Codebook> Train(const uint8_t* descriptors,
                                        std::size_t count,
                                        std::size_t dim,
                                        const KMeansOptions& options,
                                        KMeansReport* report = nullptr);

  /// A codebook from existing centroids: V x dim row-major. InvalidArgument
  /// for dim 0, a size that is not a positive multiple of dim, V >= 2^32, or a
  /// non-finite value.
  static absl::StatusOr<Codebook> FromCentroids(std::vector<float> centroids, std::size_t dim);

  /// Number of visual words V.
  std::size_t size() const { return index_.num_centroids(); }
  /// Dimension of a descriptor.
  std::size_t dim() const { return index_.dim(); }
  /// V x dim row-major.
  const std::vector<float>& centroids() const { return centroids_; }

  /// Index of the nearest word for each of `count` descriptors (count x dim()
  /// row-major; ties go to the lowest index). Runs on the calling thread only:
  /// meshseek parallelises across models (parallel.h). InvalidArgument for null
  /// descriptors with count > 0.
  absl::StatusOr<std::vector<uint32_t>> NearestCentroids(const uint8_t* descriptors,
                                                         std::size_t count) const;

  /// The bag-of-features histogram of one model: for each word, the fraction
  /// of the `count` descriptors whose nearest word it is. Length size(), sums
  /// to 1 (up to float rounding). InvalidArgument when count is 0: a model
  /// without descriptors has no histogram, and a uniform or zero one would
  /// silently rank it among the others.
  absl::StatusOr<std::vector<float>> Encode(const uint8_t* descriptors, std::size_t count) const;

  /// The serialised form described above.
  std::string Serialize() const;
  /// Parses Serialize()'s output. InvalidArgument naming what is wrong: too
  /// short, bad magic, unknown version, zero or inconsistent sizes, checksum
  /// mismatch, non-finite values.
  static absl::StatusOr<Codebook> Deserialize(absl::string_view bytes);

 private:
  Codebook(std::vector<float> centroids, std::size_t size, std::size_t dim);

  std::vector<float> centroids_;
  NearestCentroidIndex index_;
};

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_BOF_CODEBOOK_H_
