// Seeded, deterministic k-means (Lloyd) for learning a visual vocabulary
// (docs/design.md 2.7: the codebook is k-means over local features sampled from the
// collection's own models).
//
// Steps:
//   1. Sub-sample the training set to at most max_points_per_centroid points per
//      centroid (as Faiss does): Lloyd costs n * k * dim per iteration, and a few
//      hundred points per centroid already pin a centroid down. Warn below
//      min_points_per_centroid.
//   2. Seed (KMeansOptions::seeding) with k-means++ run on a smaller random subset
//      (init_points_per_centroid per centroid). Why not plain random points
//      (Faiss's default): depth-image SIFT has many identical descriptors (flat
//      patches give all-zero gradients), so random seeds land on duplicates and
//      start with clusters that are empty by construction; k-means++ never picks
//      a point at distance 0 from a chosen seed and spreads seeds over the data.
//      Why on a subset: k-means++ is k sequential passes over its points
//      (O(m k dim)); on 8 points per centroid it costs a fraction of one Lloyd
//      iteration over 256 per centroid, while the seeds only need to be spread,
//      not precise: Lloyd refines them. k-means++ is still O(k^2) however
//      small the subset (V = 20,000: 0.8 TFLOP of sequential passes, minutes),
//      so large vocabularies are seeded with k distinct random training points
//      instead: distinct by value, which keeps what k-means++ was chosen for
//      (no seed duplicates the all-zero descriptor).
//   3. Lloyd iterations: nearest-centroid assignment, exact (nearest_centroid.h)
//      or, for large vocabularies, approximate (approximate_nearest_centroid.h;
//      KMeansOptions::assignment), then centroid = mean of its points. Stop
//      after max_iterations, when no assignment changes, or when an iteration
//      lowers the objective by less than `tolerance` (relative).
//   4. Empty clusters are split Faiss-style: the empty centroid takes a copy of
//      the centroid of the largest cluster (lowest index on ties), and the two
//      are pushed apart by a relative 1/1024 in opposite directions,
//      alternating the sign per coordinate, so the next assignment divides the
//      large cluster between them.
//
// Determinism: every random choice comes from one std::mt19937_64 seeded with
// options.seed, turned into numbers by meshseek's own arithmetic (not the
// library-defined std distributions), so the same input and seed give the same
// centroids with any standard library. Every reduction runs in a fixed order
// (per-centroid sums over points in index order, in double), and both
// assignment searches are bit-identical for any thread count, so the result is
// bit-identical for any num_threads, with either assignment.
#ifndef MESHSEEK_COMMON_BOF_KMEANS_H_
#define MESHSEEK_COMMON_BOF_KMEANS_H_

#include <cstddef>
#include <cstdint>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "common/bof/approximate_nearest_centroid.h"

namespace meshseek {

struct KMeansOptions {
  /// How a point finds its nearest centroid, in the Lloyd iterations and, for
  /// a Codebook trained with these options, when encoding.
  enum class Assignment {
    /// kExact below approximate_min_centroids centroids, kApproximate from there.
    kAuto = 0,
    /// The true nearest centroid (nearest_centroid.h).
    kExact = 1,
    /// The nearest among the centroids of the approximate_probes nearest of
    /// approximate_groups groups (approximate_nearest_centroid.h).
    kApproximate = 2,
    /// Not flat k-means: the words are the leaves of a vocabulary tree of
    /// tree_depth levels, learnt by hierarchical k-means and searched by
    /// descending it (vocabulary_tree.h). A Codebook trains one; TrainKMeans
    /// refuses it.
    kTree = 3,
  };
  /// How the initial centroids are chosen (step 2 above).
  enum class Seeding {
    /// kKMeansPlusPlus up to kmeans_plus_plus_max_centroids, kRandomDistinct above.
    kAuto,
    /// k-means++ on init_points_per_centroid points per centroid; O(k^2).
    kKMeansPlusPlus,
    /// k training points drawn at random, skipping values already drawn; O(n).
    kRandomDistinct,
  };

  /// Number of centroids k, i.e. the vocabulary size V (docs/design.md 2.7: 500..5,000).
  int num_centroids = 1000;
  /// Maximum number of Lloyd iterations (one assignment and one update each).
  /// Faiss's default. One iteration over 100,000 x 128 points with V = 1,000
  /// takes 0.73 s on one core of the development machine, 0.37 s on two.
  int max_iterations = 25;
  /// Stop once an iteration lowers the objective (mean squared distance to the
  /// nearest centroid) by less than this fraction of it; 0 runs max_iterations
  /// unless assignments stop changing.
  double tolerance = 1e-4;
  /// Seed for sub-sampling and seeding; same input and seed give the same centroids.
  uint64_t seed = 0;
  /// Threads for assignment and update (<= 0: all cores). Results do not depend on it.
  int num_threads = 0;
  /// The training set is sub-sampled (uniformly, without replacement) to at most
  /// this many points per centroid. Faiss's default.
  int max_points_per_centroid = 256;
  /// Below this many training points per centroid a warning is logged: the
  /// centroids are then poorly estimated. Faiss's default.
  int min_points_per_centroid = 39;
  /// k-means++ seeding runs on a random subset of this many points per centroid
  /// (or on the whole training set if that is smaller).
  int init_points_per_centroid = 8;
  /// See Assignment.
  Assignment assignment = Assignment::kAuto;
  /// kAuto's threshold on num_centroids. Measured on the development sets'
  /// DLD-SIFT features at V = 2,000 (bench/results/codebook.txt), approximate
  /// assignment with k-means++ seeding reached a lower k-means objective than
  /// exact (McGill 34,331 against 34,407, PSB train 47,644 against 47,860) and
  /// the same first tier (75.0 and 75.0, 37.6 and 37.5) in a third of the CPU
  /// time, encoding in a third too; at V = 10,000 exact is 7 times slower.
  /// Below the threshold (small test vocabularies) exact search is both fast
  /// and what the approximate one would reduce to.
  int approximate_min_centroids = 1000;
  /// Number of groups G of the approximate search; 0 picks sqrt(probes * V),
  /// which minimises the distances computed per point (G + probes * V / G).
  /// At most num_centroids.
  int approximate_groups = 0;
  /// Groups searched per point by the approximate search. More probes: closer
  /// to exact, proportionally slower. At V = 20,000 on SIFT-like descriptors
  /// 4 / 8 / 16 probes find the exact nearest word for 96.3 / 99.0 / 99.7% of
  /// them at 0.16 / 0.20 / 0.30 of exact search's time (bench/results/codebook.txt).
  int approximate_probes = 8;
  /// Not a parameter of the collection but of one call: when non-zero, the
  /// points given are the rows that step 1 draws from a set of this many
  /// (KMeansTrainingRows), in order, not the whole set, and training goes on
  /// exactly as it would on the whole set (the same centroids bit for bit).
  /// It lets a client send a codebook service only what k-means reads: a
  /// quarter of McGill's BF-DSIFT descriptors (1.6 M of 6.4 M, 205 of 823 MB).
  /// Then it must exceed num_centroids x max_points_per_centroid and the
  /// points given be that many (InvalidArgument otherwise).
  uint64_t sampled_from = 0;
  /// See Seeding.
  Seeding seeding = Seeding::kAuto;
  /// Levels of a vocabulary tree (assignment kTree), 1..8: about
  /// depth x V^(1/depth) distances a descriptor (105 at V = 40,000, depth 3).
  int tree_depth = 3;
  /// Nodes a vocabulary tree's search keeps at each level, 1..64 (1: the plain
  /// descent; vocabulary_tree.h).
  int tree_probes = 1;
  /// kAuto's threshold for k-means++: O(V^2 init_points_per_centroid dim)
  /// multiply-adds, 4 G at V = 2,000 but 410 G at V = 20,000, where random
  /// distinct seeds cost nothing and Lloyd catches up (bench/results/codebook.txt).
  int kmeans_plus_plus_max_centroids = 5000;

  /// InvalidArgument naming the first bad field and its value.
  absl::Status Validate() const;

  /// Whether assignment (kAuto resolved with num_centroids) is approximate.
  bool UsesApproximateAssignment() const;
  /// The approximate search's parameters for num_centroids, resolved
  /// (ApproximateSearchParams::Resolve).
  ApproximateSearchParams ResolvedApproximateParams() const;
  /// Whether seeding (kAuto resolved) is k-means++.
  bool UsesKMeansPlusPlus() const;
};

/// "auto", "exact", "approximate" or "tree": the names flags and the wire use.
const char* KMeansAssignmentName(KMeansOptions::Assignment assignment);
/// The assignment named so ("" is "auto"), or InvalidArgument.
absl::StatusOr<KMeansOptions::Assignment> ParseKMeansAssignment(absl::string_view name);

/// What TrainKMeans did.
struct KMeansReport {
  std::size_t input_points = 0;          ///< points given
  std::size_t training_points = 0;       ///< points after sub-sampling
  std::size_t init_points = 0;           ///< points k-means++ seeding ran on
  int iterations = 0;                    ///< Lloyd iterations run
  bool converged = false;                ///< stopped by tolerance or unchanged assignments
  std::size_t empty_clusters_split = 0;  ///< empty clusters re-seeded, over all iterations
  bool approximate_assignment = false;   ///< whether assignment was approximate
  ApproximateSearchParams approximate;   ///< its parameters, when it was
  bool kmeans_plus_plus = false;         ///< seeded by k-means++ (else random distinct)
  /// Mean squared distance of the training points to their nearest centroid, at
  /// each iteration's assignment (before its update).
  std::vector<double> objective;
};

/// Learns options.num_centroids centroids from `n` row-major points of `dim`
/// coordinates. Returns num_centroids x dim row-major floats.
///
/// Errors (InvalidArgument, carrying the bad values): invalid options, dim 0,
/// null points, fewer points than centroids, a non-finite coordinate (the
/// message names the point and coordinate).
absl::StatusOr<std::vector<float>> TrainKMeans(const float* points,
                                               std::size_t n,
                                               std::size_t dim,
                                               const KMeansOptions& options,
                                               KMeansReport* report = nullptr);

/// The rows of a set of `n` points that TrainKMeans trains on (step 1), in
/// increasing order: every row when n is at most num_centroids x
/// max_points_per_centroid, else the seeded sample (see sampled_from).
std::vector<std::size_t> KMeansTrainingRows(std::size_t n, const KMeansOptions& options);

/// The same for uint8 points (quantised SIFT descriptors). The sub-sampled
/// training set stays uint8 (4x less memory than a float copy: 1.3M points for
/// V = 5,000 are 164 MB) and is converted block by block when searched. Gives
/// the same centroids as the float overload on the same values.
absl::StatusOr<std::vector<float>> TrainKMeans(const uint8_t* points,
                                               std::size_t n,
                                               std::size_t dim,
                                               const KMeansOptions& options,
                                               KMeansReport* report = nullptr);

namespace internal {

/// TrainKMeans without the summary line it logs at INFO: the approximate
/// search groups the centroids by k-means once per Lloyd iteration, and a
/// vocabulary tree runs one k-means a node.
absl::StatusOr<std::vector<float>> TrainKMeansQuietly(const float* points,
                                                      std::size_t n,
                                                      std::size_t dim,
                                                      const KMeansOptions& options,
                                                      KMeansReport* report);
absl::StatusOr<std::vector<float>> TrainKMeansQuietly(const uint8_t* points,
                                                      std::size_t n,
                                                      std::size_t dim,
                                                      const KMeansOptions& options,
                                                      KMeansReport* report);

/// Step 4 above, exposed for tests: for each c with counts[c] == 0 (in
/// increasing c), splits the cluster with the largest count (lowest index on
/// ties) between it and c, halving its count. `centroids` is counts.size() x
/// dim. Returns the number of clusters split.
std::size_t SplitEmptyClusters(std::size_t dim,
                               std::vector<float>* centroids,
                               std::vector<std::size_t>* counts);

}  // namespace internal
}  // namespace meshseek

#endif  // MESHSEEK_COMMON_BOF_KMEANS_H_
