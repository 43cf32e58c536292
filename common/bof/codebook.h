// A visual vocabulary for bag-of-features (docs/design.md 2.7): V centroids
// ("visual words") in descriptor space, learnt by k-means over local features
// of the collection's own models, and the encoder that turns one model's local
// descriptors into a normalised histogram of nearest words.
//
// Encoding uses the same kind of nearest-centroid search that assigned points
// during training (KMeansOptions::assignment), with the same parameters:
//  - exact (nearest_centroid.h; the default below V = 1,000), about 15 ms for
//    2,048 descriptors against V = 1,000 on one core, identical on every
//    machine and thread count;
//  - approximate (approximate_nearest_centroid.h; large vocabularies), the
//    two-level search: 81 ms CPU per model of 2,500 descriptors at V = 20,000
//    against 395 ms exact, finding the exact nearest word for 96.6% of them.
//    A word found is the one training would have assigned the same
//    descriptor to, so histograms match the clusters;
//  - tree (vocabulary_tree.h): the words are a vocabulary tree's leaves, and
//    a descriptor's word is the leaf its descent reaches, as in training.
//
// A Codebook is immutable once made; its const methods may be called from
// several threads at once.
//
// Serialised form (for the codebook service to persist), little-endian:
//   exact:        "MSCB" | uint32 version (1) | uint64 V | uint64 dim |
//                 V * dim float32, row-major | uint64 FNV-1a 64 hash of every
//                 preceding byte;
//   approximate:  "MSCB" | uint32 version (2) | uint64 V | uint64 dim |
//                 uint32 groups | uint32 probes | V * dim float32 | hash;
//   tree:         "MSCB" | uint32 version (3) | uint64 V | uint64 dim |
//                 uint32 N nodes | uint32 probes | N * (uint32 first_child, uint32
//                 num_children, uint32 leaf), breadth first |
//                 (N - 1) * dim float32, the non-root nodes' centres | hash.
// Exact codebooks keep writing version 1, so their bytes are unchanged and
// older readers read them. The approximate search's grouping is rebuilt from
// the centroids (it is a deterministic function of them, groups and probes).
// Deserialize checks every part and rejects anything else.
#ifndef MESHSEEK_COMMON_BOF_CODEBOOK_H_
#define MESHSEEK_COMMON_BOF_CODEBOOK_H_

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "common/bof/approximate_nearest_centroid.h"
#include "common/bof/kmeans.h"
#include "common/bof/nearest_centroid.h"
#include "common/bof/vocabulary_tree.h"

namespace meshseek {

class Codebook {
 public:
  /// Learns a codebook of options.num_centroids words by k-means (kmeans.h)
  /// over `count` row-major uint8 descriptors of `dim` values each (a sample
  /// of the collection's local features; kSiftDimension, 128, for SIFT). The
  /// codebook encodes with the assignment the training used
  /// (options.UsesApproximateAssignment() and its resolved parameters).
  /// Errors are TrainKMeans's.
  static absl::StatusOr<Codebook> Train(const uint8_t* descriptors,
                                        std::size_t count,
                                        std::size_t dim,
                                        const KMeansOptions& options,
                                        KMeansReport* report = nullptr);

  /// A codebook from existing centroids: V x dim row-major, encoding by exact
  /// search, or by approximate search with `approximate` when given.
  /// InvalidArgument for dim 0, a size that is not a positive multiple of dim,
  /// V >= 2^32, a non-finite value, or approximate parameters outside
  /// 1 <= probes <= groups <= V.
  static absl::StatusOr<Codebook> FromCentroids(
      std::vector<float> centroids,
      std::size_t dim,
      std::optional<ApproximateSearchParams> approximate = std::nullopt);

  /// Number of visual words V.
  std::size_t size() const { return size_; }
  /// Dimension of a descriptor.
  std::size_t dim() const { return dim_; }
  /// V x dim row-major.
  const std::vector<float>& centroids() const { return centroids_; }
  /// The approximate search's parameters when the codebook encodes with it;
  /// nullopt when it encodes by exact search.
  std::optional<ApproximateSearchParams> approximate() const;
  /// The vocabulary tree whose leaves are the words, or nullptr.
  const VocabularyTree* tree() const { return tree_.get(); }

  /// Index of the nearest word for each of `count` descriptors (count x dim()
  /// row-major; ties go to the lowest index), by the codebook's search (exact,
  /// or approximate: see above). Runs on the calling thread only:
  /// meshseek parallelises across models (parallel.h). InvalidArgument for null
  /// descriptors with count > 0. On up to `num_threads` threads (<= 1: the
  /// calling thread), blocks of descriptors apart: the same words for any
  /// count (a query's encoding asks for the cores, docs/design.md 1.1).
  absl::StatusOr<std::vector<uint32_t>> NearestCentroids(const uint8_t* descriptors,
                                                         std::size_t count,
                                                         int num_threads = 1) const;

  /// The bag-of-features histogram of one model: for each word, the fraction
  /// of the `count` descriptors whose nearest word it is. Length size(), sums
  /// to 1 (up to float rounding). InvalidArgument when count is 0: a model
  /// without descriptors has no histogram, and a uniform or zero one would
  /// silently rank it among the others, and when `dimension` is not the
  /// codebook's (features of another method). `num_threads` as for
  /// NearestCentroids.
  absl::StatusOr<std::vector<float>> Encode(const uint8_t* descriptors,
                                            std::size_t count,
                                            std::size_t dimension,
                                            int num_threads = 1) const;

  /// The serialised form described above.
  std::string Serialize() const;
  /// Parses Serialize()'s output. InvalidArgument naming what is wrong: too
  /// short, bad magic, unknown version, zero or inconsistent sizes, checksum
  /// mismatch, non-finite values.
  static absl::StatusOr<Codebook> Deserialize(absl::string_view bytes);

 private:
  Codebook(std::vector<float> centroids,
           std::size_t size,
           std::size_t dim,
           const std::optional<ApproximateSearchParams>& approximate,
           int num_threads);
  explicit Codebook(VocabularyTree tree);
  static absl::StatusOr<Codebook> DeserializeTree(absl::string_view bytes);

  std::vector<float> centroids_;
  std::size_t size_ = 0;
  std::size_t dim_ = 0;
  // Exactly one of the three is built: index_ for exact search, approximate_
  // or tree_ (shared: immutable, and copies of a Codebook need not rebuild
  // them) otherwise.
  NearestCentroidIndex index_;
  std::shared_ptr<const ApproximateNearestCentroidIndex> approximate_;
  std::shared_ptr<const VocabularyTree> tree_;
};

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_BOF_CODEBOOK_H_
