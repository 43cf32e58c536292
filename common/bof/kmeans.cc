#include "common/bof/kmeans.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <numeric>
#include <random>
#include <string>
#include <type_traits>
#include <unordered_set>

#include "absl/strings/str_cat.h"
#include "absl/time/clock.h"
#include "common/base/logging.h"
#include "common/base/parallel.h"
#include "common/base/status_macros.h"
#include "common/bof/nearest_centroid.h"

namespace meshseek {
namespace {

// Faiss's split perturbation (Clustering.cpp, EPS = 1 / 1024).
constexpr float kSplitEpsilon = 1.0f / 1024.0f;
// Points per ParallelFor item in the k-means++ distance update.
constexpr std::size_t kInitPointsPerTask = 1024;

using Rng = std::mt19937_64;

// Uniform integer in [0, range). The modulo bias is below range / 2^64.
std::size_t UniformIndex(Rng& rng, std::size_t range) {
  return static_cast<std::size_t>(rng() % static_cast<uint64_t>(range));
}

// Uniform double in [0, 1) from the top 53 bits.
double UniformUnit(Rng& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

// `m` distinct indices of [0, n), increasing, uniformly among all such sets
// (Knuth's selection sampling, Algorithm S: O(n) draws, no index array).
std::vector<std::size_t> SampleIndices(std::size_t n, std::size_t m, Rng& rng) {
  std::vector<std::size_t> out;
  out.reserve(m);
  for (std::size_t i = 0; i < n && out.size() < m; ++i) {
    if (UniformIndex(rng, n - i) < m - out.size()) out.push_back(i);
  }
  return out;
}

typedef float Float4 __attribute__((vector_size(16)));

// ||a - b||^2 with eight lanes (two vectors) summed in a fixed order.
float SquaredDistance(const float* a, const float* b, std::size_t dim) {
  Float4 acc0 = {}, acc1 = {};
  std::size_t d = 0;
  for (; d + 8 <= dim; d += 8) {
    Float4 a0, a1, b0, b1;
    std::memcpy(&a0, a + d, sizeof(a0));
    std::memcpy(&a1, a + d + 4, sizeof(a1));
    std::memcpy(&b0, b + d, sizeof(b0));
    std::memcpy(&b1, b + d + 4, sizeof(b1));
    const Float4 e0 = a0 - b0, e1 = a1 - b1;
    acc0 += e0 * e0;
    acc1 += e1 * e1;
  }
  float tail = 0.0f;
  for (; d < dim; ++d) tail += (a[d] - b[d]) * (a[d] - b[d]);
  const Float4 s = acc0 + acc1;
  return ((s[0] + s[1]) + (s[2] + s[3])) + tail;
}

absl::Status CheckFinite(const float* points, std::size_t n, std::size_t dim) {
  for (std::size_t i = 0; i < n * dim; ++i) {
    if (!std::isfinite(points[i])) {
      return absl::InvalidArgumentError(
          absl::StrCat("k-means: point ", i / dim, ", coordinate ", i % dim, " is ", points[i]));
    }
  }
  return absl::OkStatus();
}
absl::Status CheckFinite(const uint8_t*, std::size_t, std::size_t) { return absl::OkStatus(); }

// k-means++ (Arthur & Vassilvitskii 2007) on `m` rows of `init`: each next
// seed is drawn with probability proportional to its squared distance to the
// nearest seed so far. Returns k x dim seeds. If the rows have fewer than k
// distinct values the remaining seeds are random rows (duplicates), which
// Lloyd's empty-cluster split then deals with.
std::vector<float> SeedKMeansPlusPlus(const std::vector<float>& init,
                                      std::size_t m,
                                      std::size_t dim,
                                      std::size_t k,
                                      int num_threads,
                                      Rng& rng) {
  std::vector<float> seeds(k * dim);
  auto take = [&](std::size_t c, std::size_t row) {
    std::copy_n(&init[row * dim], dim, &seeds[c * dim]);
  };
  take(0, UniformIndex(rng, m));
  std::vector<float> nearest(m, std::numeric_limits<float>::infinity());
  const std::size_t num_tasks = (m + kInitPointsPerTask - 1) / kInitPointsPerTask;
  std::size_t c = 1;
  for (;; ++c) {
    const float* seed = &seeds[(c - 1) * dim];
    ParallelFor(num_tasks, num_threads, [&](std::size_t task) {
      const std::size_t end = std::min(m, (task + 1) * kInitPointsPerTask);
      for (std::size_t i = task * kInitPointsPerTask; i < end; ++i) {
        nearest[i] = std::min(nearest[i], SquaredDistance(&init[i * dim], seed, dim));
      }
    });
    if (c == k) break;
    double total = 0.0;
    for (float v : nearest) total += v;
    if (!(total > 0.0)) break;  // every row coincides with a seed
    const double target = UniformUnit(rng) * total;
    double cumulative = 0.0;
    std::size_t pick = m;
    for (std::size_t i = 0; i < m; ++i) {
      if (nearest[i] <= 0.0f) continue;
      pick = i;  // rounding can leave target >= the final sum: keep the last candidate
      cumulative += nearest[i];
      if (cumulative > target) break;
    }
    take(c, pick);
  }
  if (c < k) {
    MESHSEEK_LOG(WARNING) << "k-means: the " << m << " seeding points have only " << c
                          << " distinct values for " << k
                          << " centroids; the rest start as duplicates";
    for (; c < k; ++c) take(c, UniformIndex(rng, m));
  }
  return seeds;
}

// k distinct rows of `train` (by value), visited in a random order: a
// partial Fisher-Yates shuffle stops as soon as k distinct values have been
// seen. If there are fewer than k, the rest are duplicates of random rows, as
// in SeedKMeansPlusPlus. Sets *examined to the rows looked at.
template <typename T>
std::vector<float> SeedRandomDistinct(const T* train,
                                      std::size_t n,
                                      std::size_t dim,
                                      std::size_t k,
                                      Rng& rng,
                                      std::size_t* examined) {
  std::vector<float> seeds(k * dim);
  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::unordered_set<std::string> seen;
  seen.reserve(2 * k);
  std::size_t c = 0, i = 0;
  for (; i < n && c < k; ++i) {
    std::swap(order[i], order[i + UniformIndex(rng, n - i)]);
    const T* row = train + order[i] * dim;
    if (!seen.emplace(reinterpret_cast<const char*>(row), dim * sizeof(T)).second) continue;
    for (std::size_t d = 0; d < dim; ++d) seeds[c * dim + d] = static_cast<float>(row[d]);
    ++c;
  }
  *examined = i;
  if (c < k) {
    MESHSEEK_LOG(WARNING) << "k-means: the " << n << " training points have only " << c
                          << " distinct values for " << k
                          << " centroids; the rest start as duplicates";
    for (; c < k; ++c) {
      const T* row = train + UniformIndex(rng, n) * dim;
      for (std::size_t d = 0; d < dim; ++d) seeds[c * dim + d] = static_cast<float>(row[d]);
    }
  }
  return seeds;
}

template <typename T>
absl::StatusOr<std::vector<float>> TrainKMeansImpl(const T* points,
                                                   std::size_t n,
                                                   std::size_t dim,
                                                   const KMeansOptions& options,
                                                   KMeansReport* report,
                                                   bool log_summary) {
  MESHSEEK_RETURN_IF_ERROR(options.Validate());
  if (options.assignment == KMeansOptions::Assignment::kTree) {
    return absl::InvalidArgumentError(
        "k-means: a vocabulary tree (assignment 'tree') is trained by VocabularyTree::Train");
  }
  const std::size_t k = static_cast<std::size_t>(options.num_centroids);
  if (dim == 0) return absl::InvalidArgumentError("k-means: dim must be >= 1, got 0");
  if (n < k) {
    return absl::InvalidArgumentError(
        absl::StrCat("k-means: got ", n, " training points for ", k, " centroids"));
  }
  if (points == nullptr) return absl::InvalidArgumentError("k-means: points is null");
  MESHSEEK_RETURN_IF_ERROR(CheckFinite(points, n, dim));

  KMeansReport local_report;
  KMeansReport& rep = report != nullptr ? *report : local_report;
  rep = KMeansReport();
  rep.input_points = n;
  Rng rng(options.seed);
  const absl::Time start = absl::Now();

  // 1. Sub-sample.
  const std::size_t max_train = k * static_cast<std::size_t>(options.max_points_per_centroid);
  std::vector<T> sampled;
  const T* train = points;
  std::size_t n_train = n;
  if (options.sampled_from > 0) {
    // The caller sent the sample (KMeansTrainingRows): draw what drawing it
    // drew, so that seeding goes on from the same generator state.
    if (options.sampled_from <= max_train || n != max_train) {
      return absl::InvalidArgumentError(absl::StrCat(
          "k-means: ", n, " points sampled from ", options.sampled_from, "; a sample of ",
          options.sampled_from, " has ", std::min<std::size_t>(options.sampled_from, max_train),
          options.sampled_from <= max_train ? " points and is the whole set" : " points"));
    }
    rep.input_points = options.sampled_from;
    SampleIndices(options.sampled_from, max_train, rng);
  } else if (n > max_train) {
    const std::vector<std::size_t> rows = SampleIndices(n, max_train, rng);
    sampled.resize(max_train * dim);
    for (std::size_t i = 0; i < max_train; ++i) {
      std::copy_n(points + rows[i] * dim, dim, &sampled[i * dim]);
    }
    train = sampled.data();
    n_train = max_train;
  }
  rep.training_points = n_train;
  if (n_train < k * static_cast<std::size_t>(options.min_points_per_centroid)) {
    MESHSEEK_LOG(WARNING) << "k-means: " << n_train << " training points for " << k
                          << " centroids (" << n_train / k << " per centroid); below "
                          << options.min_points_per_centroid
                          << " per centroid the centroids are poorly estimated";
  }

  // 2. Seed.
  std::vector<float> centroids;
  rep.kmeans_plus_plus = options.UsesKMeansPlusPlus();
  if (rep.kmeans_plus_plus) {
    const std::size_t m = std::min(
        n_train, std::max(k, k * static_cast<std::size_t>(options.init_points_per_centroid)));
    std::vector<float> init(m * dim);
    {
      const std::vector<std::size_t> rows = SampleIndices(n_train, m, rng);
      for (std::size_t i = 0; i < m; ++i) {
        for (std::size_t d = 0; d < dim; ++d) {
          init[i * dim + d] = static_cast<float>(train[rows[i] * dim + d]);
        }
      }
    }
    rep.init_points = m;
    centroids = SeedKMeansPlusPlus(init, m, dim, k, options.num_threads, rng);
  } else {
    centroids = SeedRandomDistinct(train, n_train, dim, k, rng, &rep.init_points);
  }

  // 3. Lloyd.
  rep.approximate_assignment = options.UsesApproximateAssignment();
  if (rep.approximate_assignment) rep.approximate = options.ResolvedApproximateParams();
  auto assign = [&](const std::vector<float>& c, uint32_t* labels, float* distances) {
    if (rep.approximate_assignment) {
      ApproximateNearestCentroidIndex(c.data(), k, dim, rep.approximate, options.num_threads)
          .Search(train, n_train, options.num_threads, labels, distances);
    } else {
      NearestCentroidIndex(c.data(), k, dim)
          .Search(train, n_train, options.num_threads, labels, distances);
    }
  };
  std::vector<uint32_t> labels(n_train), previous_labels;
  std::vector<float> distances(n_train);
  std::vector<std::size_t> offsets(k + 1), order(n_train), counts(k);
  double previous_objective = 0.0;
  bool split_before = false;
  for (int it = 0; it < options.max_iterations; ++it) {
    assign(centroids, labels.data(), distances.data());
    double objective = 0.0;
    for (float v : distances) objective += v;
    objective /= static_cast<double>(n_train);
    rep.objective.push_back(objective);
    const bool unchanged = labels == previous_labels;

    // Bucket the points by label (a counting sort, so each bucket lists its
    // points in increasing index), then average each bucket in double: the
    // summation order is fixed whatever the thread count.
    std::fill(offsets.begin(), offsets.end(), 0);
    for (uint32_t label : labels) ++offsets[label + 1];
    for (std::size_t c = 0; c < k; ++c) offsets[c + 1] += offsets[c];
    for (std::size_t c = 0; c < k; ++c) counts[c] = offsets[c + 1] - offsets[c];
    {
      std::vector<std::size_t> next(offsets.begin(), offsets.end() - 1);
      for (std::size_t i = 0; i < n_train; ++i) order[next[labels[i]]++] = i;
    }
    ParallelFor(k, options.num_threads, [&](std::size_t c) {
      if (counts[c] == 0) return;
      std::vector<double> sum(dim, 0.0);
      for (std::size_t j = offsets[c]; j < offsets[c + 1]; ++j) {
        const T* x = train + order[j] * dim;
        for (std::size_t d = 0; d < dim; ++d) sum[d] += static_cast<double>(x[d]);
      }
      for (std::size_t d = 0; d < dim; ++d) {
        centroids[c * dim + d] = static_cast<float>(sum[d] / static_cast<double>(counts[c]));
      }
    });
    const std::size_t split = internal::SplitEmptyClusters(dim, &centroids, &counts);
    rep.empty_clusters_split += split;
    rep.iterations = it + 1;
    MESHSEEK_LOG(DEBUG) << "k-means iteration " << it << ": objective " << objective << ", "
                        << split << " empty clusters split";

    // A split perturbs centroids and may raise the next objective slightly, so
    // the relative-decrease test only applies after an iteration without one.
    if (unchanged && !split_before) {
      rep.converged = true;
      break;
    }
    if (it > 0 && !split_before &&
        previous_objective - objective <= options.tolerance * previous_objective) {
      rep.converged = true;
      break;
    }
    previous_objective = objective;
    split_before = split > 0;
    previous_labels.swap(labels);
    labels.resize(n_train);
  }
  if (log_summary) {
    MESHSEEK_LOG(INFO) << "k-means: " << k << " centroids from " << n_train << " of "
                       << rep.input_points
                       << " points, " << rep.iterations << " iterations"
                       << (rep.converged ? " (converged)" : "") << ", "
                       << (rep.approximate_assignment
                               ? absl::StrCat("approximate assignment (",
                                              rep.approximate.groups,
                                              " groups, ",
                                              rep.approximate.probes,
                                              " probes)")
                               : std::string("exact assignment"))
                       << ", mean squared distance "
                       << (rep.objective.empty() ? 0.0 : rep.objective.back()) << ", "
                       << absl::FormatDuration(absl::Trunc(absl::Now() - start, absl::Milliseconds(1)));
  }
  return centroids;
}

}  // namespace

absl::Status KMeansOptions::Validate() const {
  auto bad = [](const char* field, auto value, const char* rule) {
    return absl::InvalidArgumentError(
        absl::StrCat("KMeansOptions: ", field, " must be ", rule, ", got ", value));
  };
  if (num_centroids < 1) return bad("num_centroids", num_centroids, ">= 1");
  if (max_iterations < 1) return bad("max_iterations", max_iterations, ">= 1");
  if (!(tolerance >= 0.0 && tolerance < 1.0)) return bad("tolerance", tolerance, "in [0, 1)");
  if (max_points_per_centroid < 1) {
    return bad("max_points_per_centroid", max_points_per_centroid, ">= 1");
  }
  if (min_points_per_centroid < 1) {
    return bad("min_points_per_centroid", min_points_per_centroid, ">= 1");
  }
  if (min_points_per_centroid > max_points_per_centroid) {
    return bad("min_points_per_centroid",
               min_points_per_centroid,
               absl::StrCat("<= max_points_per_centroid (", max_points_per_centroid, ")").c_str());
  }
  if (init_points_per_centroid < 1) {
    return bad("init_points_per_centroid", init_points_per_centroid, ">= 1");
  }
  if (assignment != Assignment::kAuto && assignment != Assignment::kExact &&
      assignment != Assignment::kApproximate && assignment != Assignment::kTree) {
    return bad("assignment", static_cast<int>(assignment), "kAuto, kExact, kApproximate or kTree");
  }
  if (tree_depth < 1 || tree_depth > 8) return bad("tree_depth", tree_depth, "in [1, 8]");
  if (tree_probes < 1 || tree_probes > 64) return bad("tree_probes", tree_probes, "in [1, 64]");
  if (assignment == Assignment::kTree && num_centroids < 2) {
    return bad("num_centroids", num_centroids, ">= 2 for a vocabulary tree");
  }
  if (approximate_min_centroids < 1) {
    return bad("approximate_min_centroids", approximate_min_centroids, ">= 1");
  }
  if (kmeans_plus_plus_max_centroids < 0) {
    return bad("kmeans_plus_plus_max_centroids", kmeans_plus_plus_max_centroids, ">= 0");
  }
  if (approximate_groups < 0) {
    return bad("approximate_groups", approximate_groups, ">= 0 (0: automatic)");
  }
  if (approximate_groups > num_centroids) {
    return bad("approximate_groups",
               approximate_groups,
               absl::StrCat("<= num_centroids (", num_centroids, ")").c_str());
  }
  if (approximate_probes < 1) return bad("approximate_probes", approximate_probes, ">= 1");
  if (approximate_groups > 0 && approximate_probes > approximate_groups) {
    return bad("approximate_probes",
               approximate_probes,
               absl::StrCat("<= approximate_groups (", approximate_groups, ")").c_str());
  }
  if (seeding != Seeding::kAuto && seeding != Seeding::kKMeansPlusPlus &&
      seeding != Seeding::kRandomDistinct) {
    return bad("seeding", static_cast<int>(seeding), "kAuto, kKMeansPlusPlus or kRandomDistinct");
  }
  return absl::OkStatus();
}

bool KMeansOptions::UsesApproximateAssignment() const {
  switch (assignment) {
    case Assignment::kExact:
    case Assignment::kTree:
      return false;
    case Assignment::kApproximate:
      return true;
    case Assignment::kAuto:
      break;
  }
  return num_centroids >= approximate_min_centroids;
}

ApproximateSearchParams KMeansOptions::ResolvedApproximateParams() const {
  return ApproximateSearchParams::Resolve(
      approximate_groups, approximate_probes, static_cast<std::size_t>(std::max(1, num_centroids)));
}

bool KMeansOptions::UsesKMeansPlusPlus() const {
  switch (seeding) {
    case Seeding::kKMeansPlusPlus:
      return true;
    case Seeding::kRandomDistinct:
      return false;
    case Seeding::kAuto:
      break;
  }
  return num_centroids <= kmeans_plus_plus_max_centroids;
}

const char* KMeansAssignmentName(KMeansOptions::Assignment assignment) {
  switch (assignment) {
    case KMeansOptions::Assignment::kAuto:
      return "auto";
    case KMeansOptions::Assignment::kExact:
      return "exact";
    case KMeansOptions::Assignment::kApproximate:
      return "approximate";
    case KMeansOptions::Assignment::kTree:
      return "tree";
  }
  return "?";
}

absl::StatusOr<KMeansOptions::Assignment> ParseKMeansAssignment(absl::string_view name) {
  if (name.empty() || name == "auto") return KMeansOptions::Assignment::kAuto;
  if (name == "exact") return KMeansOptions::Assignment::kExact;
  if (name == "approximate") return KMeansOptions::Assignment::kApproximate;
  if (name == "tree") return KMeansOptions::Assignment::kTree;
  return absl::InvalidArgumentError(absl::StrCat(
      "k-means assignment must be 'auto', 'exact', 'approximate' or 'tree', got '", name, "'"));
}

std::vector<std::size_t> KMeansTrainingRows(std::size_t n, const KMeansOptions& options) {
  const std::size_t max_train = static_cast<std::size_t>(options.num_centroids) *
                                static_cast<std::size_t>(options.max_points_per_centroid);
  if (n <= max_train) {
    std::vector<std::size_t> all(n);
    for (std::size_t i = 0; i < n; ++i) all[i] = i;
    return all;
  }
  Rng rng(options.seed);
  return SampleIndices(n, max_train, rng);
}

absl::StatusOr<std::vector<float>> TrainKMeans(const float* points,
                                               std::size_t n,
                                               std::size_t dim,
                                               const KMeansOptions& options,
                                               KMeansReport* report) {
  return TrainKMeansImpl(points, n, dim, options, report, /*log_summary=*/true);
}

absl::StatusOr<std::vector<float>> TrainKMeans(const uint8_t* points,
                                               std::size_t n,
                                               std::size_t dim,
                                               const KMeansOptions& options,
                                               KMeansReport* report) {
  return TrainKMeansImpl(points, n, dim, options, report, /*log_summary=*/true);
}

namespace internal {

absl::StatusOr<std::vector<float>> TrainKMeansQuietly(const float* points,
                                                      std::size_t n,
                                                      std::size_t dim,
                                                      const KMeansOptions& options,
                                                      KMeansReport* report) {
  return TrainKMeansImpl(points, n, dim, options, report, /*log_summary=*/false);
}

absl::StatusOr<std::vector<float>> TrainKMeansQuietly(const uint8_t* points,
                                                      std::size_t n,
                                                      std::size_t dim,
                                                      const KMeansOptions& options,
                                                      KMeansReport* report) {
  return TrainKMeansImpl(points, n, dim, options, report, /*log_summary=*/false);
}

std::size_t SplitEmptyClusters(std::size_t dim,
                               std::vector<float>* centroids,
                               std::vector<std::size_t>* counts) {
  std::vector<std::size_t>& count = *counts;
  std::size_t split = 0;
  for (std::size_t c = 0; c < count.size(); ++c) {
    if (count[c] != 0) continue;
    const std::size_t largest =
        static_cast<std::size_t>(std::max_element(count.begin(), count.end()) - count.begin());
    if (count[largest] < 2) break;  // nothing left to split (cannot happen when n >= k)
    float* a = &(*centroids)[c * dim];
    float* b = &(*centroids)[largest * dim];
    for (std::size_t d = 0; d < dim; ++d) {
      const float up = b[d] * (1.0f + kSplitEpsilon), down = b[d] * (1.0f - kSplitEpsilon);
      a[d] = d % 2 == 0 ? up : down;
      b[d] = d % 2 == 0 ? down : up;
    }
    count[c] = count[largest] / 2;
    count[largest] -= count[c];
    ++split;
  }
  return split;
}

}  // namespace internal
}  // namespace meshseek
