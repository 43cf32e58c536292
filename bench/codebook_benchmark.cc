// Codebook training and encoding at large vocabularies (issue 9, part 3):
// exact against approximate nearest-centroid assignment (kmeans.h), on
// SIFT-like synthetic descriptors or a collection's real ones.
//
//   codebook_benchmark --experiment=train --points=1000000 --vocabulary=20000
//                      [--assignment=auto|exact|approximate] [--probes=8] [--groups=0]
//                      [--seeding=auto|kmeanspp|random] [--iterations=25]
//                      [--agreement_sample=50000] [--codebook_out=FILE]
//       Trains, then measures on a sample of the training points, against the
//       final centroids: the exact k-means objective (mean squared distance to
//       the nearest centroid), and for the approximate search with the same
//       parameters its agreement with exact search (fraction of points given
//       the exact nearest word) and its objective ratio (approximate / exact).
//   codebook_benchmark --experiment=encode --codebook_in=FILE --models=1000
//                      [--exact_models=40]
//       Encodes `models` synthetic models of 2,000-3,000 descriptors on
//       --threads threads (one model per thread, as EncodeCollection does),
//       then the first exact_models with exact search for comparison.
//   codebook_benchmark --experiment=libraries --codebook_in=FILE (built with Faiss)
//       Times nearest-centroid search of --agreement_sample points through
//       meshseek's kernels and Faiss's (IndexFlatL2 on BLAS sgemm, IndexIVFFlat
//       over the centroids, IndexHNSWFlat), with agreement against exact.
//   codebook_benchmark --experiment=collection --manifest=FILE [--vocabulary=2000]
//       The in-process pipeline (DLD-SIFT defaults) on a labelled collection,
//       features extracted once, codebook trained and evaluated with exact and
//       with approximate assignment: objective, first tier, nearest neighbour.
//
// The synthetic descriptors imitate OpenCV SIFT: 4 x 4 cells x 8 orientation
// bins of non-negative, sparse gradient energy around a few hundred thousand
// modes of Zipf-distributed popularity, plus noise, normalised as SIFT is (unit
// L2, clipped at 0.2, renormalised, x 512, saturated to uint8), with 3% all-zero
// descriptors (flat depth patches).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <iterator>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <time.h>

#include "absl/flags/flag.h"
#include "absl/flags/parse.h"
#include "common/base/parallel.h"
#include "common/bof/approximate_nearest_centroid.h"
#include "common/bof/codebook.h"
#include "common/bof/kmeans.h"
#include "common/bof/nearest_centroid.h"
#include "common/eval/manifest.h"
#include "common/eval/retrieval_metrics.h"
#include "common/pipeline/retrieval_pipeline.h"

#ifdef MESHSEEK_HAVE_FAISS
#include <faiss/IndexFlat.h>
#include <faiss/IndexHNSW.h>
#include <faiss/IndexIVFFlat.h>
#include <omp.h>
#endif

ABSL_FLAG(std::string, experiment, "train", "train, encode, libraries or collection");
ABSL_FLAG(int64_t, points, 1000000, "synthetic training descriptors");
ABSL_FLAG(int, vocabulary, 20000, "codebook size V");
ABSL_FLAG(std::string, assignment, "auto", "auto, exact, approximate or tree");
ABSL_FLAG(int, tree_depth, 3, "KMeansOptions::tree_depth (assignment tree)");
ABSL_FLAG(int, probes, 8, "KMeansOptions::approximate_probes");
ABSL_FLAG(int, groups, 0, "KMeansOptions::approximate_groups (0: automatic)");
ABSL_FLAG(std::string, seeding, "auto", "auto, kmeanspp or random");
ABSL_FLAG(int, iterations, 25, "maximum Lloyd iterations");
ABSL_FLAG(int, points_per_centroid, 256, "KMeansOptions::max_points_per_centroid");
ABSL_FLAG(int, threads, 2, "threads");
ABSL_FLAG(uint64_t, seed, 0, "k-means seed");
ABSL_FLAG(int64_t, agreement_sample, 50000, "points measured against exact search");
ABSL_FLAG(std::string, codebook_out, "", "write the trained codebook here");
ABSL_FLAG(std::string, codebook_in, "", "codebook to encode with");
ABSL_FLAG(int, models, 1000, "synthetic models to encode");
ABSL_FLAG(int, exact_models, 40, "of which encoded again with exact search");
ABSL_FLAG(std::string, manifest, "", "labelled collection (experiment=collection)");
ABSL_FLAG(std::string, probes_list, "4,8,16", "probes compared (experiment=collection, libraries)");
ABSL_FLAG(std::string, iterations_list, "25",
          "maximum Lloyd iterations compared (experiment=collection)");

namespace meshseek {
namespace {

constexpr std::size_t kDim = 128;

double Now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

// CPU time of the whole process (all threads): on a shared machine, CPU
// seconds / threads estimates the wall time on idle cores.
double CpuSeconds() {
  timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

std::vector<int> ParseList(const std::string& s) {
  std::vector<int> out;
  std::stringstream in(s);
  std::string item;
  while (std::getline(in, item, ',')) out.push_back(std::stoi(item));
  return out;
}

// SIFT-like synthetic descriptors (see the file comment).
class SiftLikeGenerator {
 public:
  SiftLikeGenerator(std::size_t num_modes, uint64_t seed) : rng_(seed), modes_(num_modes * kDim) {
    std::normal_distribution<float> normal(0.0f, 1.0f);
    for (float& v : modes_) {
      const float g = normal(rng_);
      v = g > 0.0f ? g * g : 0.0f;  // half the bins empty, the rest heavy-tailed
    }
    // Zipf(1) popularity: cumulative weights for inverse-CDF sampling.
    cumulative_.resize(num_modes);
    double total = 0.0;
    for (std::size_t m = 0; m < num_modes; ++m) cumulative_[m] = total += 1.0 / (m + 1.0);
    for (double& c : cumulative_) c /= total;
  }

  std::size_t num_modes() const { return cumulative_.size(); }

  // A mode drawn by popularity.
  std::size_t DrawMode() {
    const double u = std::uniform_real_distribution<double>(0.0, 1.0)(rng_);
    return static_cast<std::size_t>(std::lower_bound(cumulative_.begin(), cumulative_.end(), u) -
                                    cumulative_.begin());
  }

  // One descriptor near `mode` (or all zero, 3% of the time), appended to out.
  void Draw(std::size_t mode, std::vector<uint8_t>* out) {
    std::normal_distribution<float> normal(0.0f, 1.0f);
    float v[kDim];
    const bool flat = std::uniform_real_distribution<float>(0.0f, 1.0f)(rng_) < 0.03f;
    double norm = 0.0;
    for (std::size_t d = 0; d < kDim; ++d) {
      const float n1 = normal(rng_), n2 = normal(rng_);
      v[d] = flat ? 0.0f : std::max(0.0f, modes_[mode * kDim + d] * (1.0f + 0.35f * n1) +
                                               0.15f * std::abs(n2));
      norm += static_cast<double>(v[d]) * v[d];
    }
    // OpenCV's SIFT normalisation.
    const float inv = norm > 0.0 ? static_cast<float>(1.0 / std::sqrt(norm)) : 0.0f;
    double norm2 = 0.0;
    for (float& x : v) {
      x = std::min(x * inv, 0.2f);
      norm2 += static_cast<double>(x) * x;
    }
    const float scale = norm2 > 0.0 ? static_cast<float>(512.0 / std::sqrt(norm2)) : 0.0f;
    for (float x : v) out->push_back(static_cast<uint8_t>(std::min(255.0f, std::round(x * scale))));
  }

  std::vector<uint8_t> Sample(std::size_t n) {
    std::vector<uint8_t> out;
    out.reserve(n * kDim);
    for (std::size_t i = 0; i < n; ++i) Draw(DrawMode(), &out);
    return out;
  }

  // One model: descriptors from its own 150 modes (drawn by popularity).
  std::vector<uint8_t> Model(std::size_t n) {
    std::vector<std::size_t> own(150);
    for (std::size_t& m : own) m = DrawMode();
    std::vector<uint8_t> out;
    out.reserve(n * kDim);
    for (std::size_t i = 0; i < n; ++i) Draw(own[rng_() % own.size()], &out);
    return out;
  }

  std::mt19937_64& rng() { return rng_; }

 private:
  std::mt19937_64 rng_;
  std::vector<float> modes_;
  std::vector<double> cumulative_;
};

KMeansOptions OptionsFromFlags() {
  KMeansOptions o;
  o.num_centroids = absl::GetFlag(FLAGS_vocabulary);
  o.max_iterations = absl::GetFlag(FLAGS_iterations);
  o.max_points_per_centroid = absl::GetFlag(FLAGS_points_per_centroid);
  o.num_threads = absl::GetFlag(FLAGS_threads);
  o.seed = absl::GetFlag(FLAGS_seed);
  o.approximate_probes = absl::GetFlag(FLAGS_probes);
  o.approximate_groups = absl::GetFlag(FLAGS_groups);
  const std::string a = absl::GetFlag(FLAGS_assignment);
  o.assignment = ParseKMeansAssignment(a).value_or(KMeansOptions::Assignment::kAuto);
  o.tree_depth = absl::GetFlag(FLAGS_tree_depth);
  const std::string s = absl::GetFlag(FLAGS_seeding);
  o.seeding = s == "kmeanspp" ? KMeansOptions::Seeding::kKMeansPlusPlus
              : s == "random" ? KMeansOptions::Seeding::kRandomDistinct
                              : KMeansOptions::Seeding::kAuto;
  return o;
}

struct Agreement {
  double exact_objective = 0;   // mean squared distance to the exact nearest centroid
  double approx_objective = 0;  // ... to the approximate search's answer
  double agreement = 0;         // fraction with the same label
  double exact_seconds = 0, approx_seconds = 0;
};

// Exact against approximate search (params) on `n` points.
Agreement MeasureAgreement(const std::vector<float>& centroids,
                           const uint8_t* points,
                           std::size_t n,
                           const ApproximateSearchParams& params,
                           int threads) {
  const std::size_t v = centroids.size() / kDim;
  std::vector<uint32_t> exact(n), approx(n);
  std::vector<float> de(n), da(n);
  Agreement a;
  double t = CpuSeconds();
  NearestCentroidIndex(centroids.data(), v, kDim)
      .Search(points, n, threads, exact.data(), de.data());
  a.exact_seconds = CpuSeconds() - t;
  t = CpuSeconds();
  ApproximateNearestCentroidIndex index(centroids.data(), v, kDim, params, threads);
  const double build = CpuSeconds() - t;
  t = CpuSeconds();
  index.Search(points, n, threads, approx.data(), da.data());
  a.approx_seconds = CpuSeconds() - t;
  std::size_t same = 0;
  for (std::size_t i = 0; i < n; ++i) {
    same += exact[i] == approx[i];
    a.exact_objective += de[i];
    a.approx_objective += da[i];
  }
  a.exact_objective /= n;
  a.approx_objective /= n;
  a.agreement = static_cast<double>(same) / n;
  std::printf(
      "  search %zu points, V = %zu (CPU seconds): exact %.2f s, approximate (%d groups, %d "
      "probes) %.2f s + %.2f s grouping; agreement %.4f, objective ratio %.5f\n",
      n,
      v,
      a.exact_seconds,
      params.groups,
      params.probes,
      a.approx_seconds,
      build,
      a.agreement,
      a.approx_objective / a.exact_objective);
  return a;
}

int Train() {
  const KMeansOptions options = OptionsFromFlags();
  const std::size_t n = static_cast<std::size_t>(absl::GetFlag(FLAGS_points));
  double t = Now();
  SiftLikeGenerator gen(200000, 42);
  const std::vector<uint8_t> data = gen.Sample(n);
  std::printf("generated %zu SIFT-like descriptors in %.1f s\n", n, Now() - t);
  std::fflush(stdout);

  KMeansReport report;
  t = Now();
  const double cpu = CpuSeconds();
  absl::StatusOr<Codebook> codebook = Codebook::Train(data.data(), n, kDim, options, &report);
  const double seconds = Now() - t, cpu_seconds = CpuSeconds() - cpu;
  if (!codebook.ok()) {
    std::cerr << codebook.status() << "\n";
    return 1;
  }
  std::printf(
      "train V = %d on %zu of %zu points, %d threads: %.1f s wall, %.1f s CPU, %d iterations%s, "
      "%s assignment",
      options.num_centroids,
      report.training_points,
      report.input_points,
      options.num_threads,
      seconds,
      cpu_seconds,
      report.iterations,
      report.converged ? " (converged)" : "",
      report.approximate_assignment ? "approximate" : "exact");
  if (report.approximate_assignment) {
    std::printf(" (%d groups, %d probes)", report.approximate.groups, report.approximate.probes);
  }
  std::printf(", %s seeding; objective at the last iteration %.1f\n",
              report.kmeans_plus_plus ? "k-means++" : "random distinct",
              report.objective.back());
  std::fflush(stdout);

  // Measured on the first points of the training set (a uniform sample: the
  // generator draws them independently).
  const std::size_t sample =
      std::min(n, static_cast<std::size_t>(absl::GetFlag(FLAGS_agreement_sample)));
  const ApproximateSearchParams params = options.ResolvedApproximateParams();
  const Agreement a =
      MeasureAgreement(codebook->centroids(), data.data(), sample, params, options.num_threads);
  std::printf("  exact k-means objective of the final centroids on %zu points: %.1f\n",
              sample,
              a.exact_objective);
  const std::string out = absl::GetFlag(FLAGS_codebook_out);
  if (!out.empty()) {
    std::ofstream(out, std::ios::binary) << codebook->Serialize();
  }
  return 0;
}

absl::StatusOr<Codebook> ReadCodebook() {
  std::ifstream in(absl::GetFlag(FLAGS_codebook_in), std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  return Codebook::Deserialize(bytes);
}

int Encode() {
  double t = Now();
  absl::StatusOr<Codebook> codebook = ReadCodebook();
  if (!codebook.ok()) {
    std::cerr << codebook.status() << "\n";
    return 1;
  }
  std::printf("codebook V = %zu, %s search, loaded and grouped in %.2f s\n",
              codebook->size(),
              codebook->approximate() ? "approximate" : "exact",
              Now() - t);
  const int threads = absl::GetFlag(FLAGS_threads);
  SiftLikeGenerator gen(200000, 7);
  const std::size_t num_models = static_cast<std::size_t>(absl::GetFlag(FLAGS_models));
  std::vector<std::vector<uint8_t>> models(num_models);
  std::size_t total = 0;
  for (auto& m : models) {
    m = gen.Model(2000 + gen.rng()() % 1001);
    total += m.size() / kDim;
  }
  t = Now();
  const double cpu = CpuSeconds();
  std::vector<std::vector<float>> histograms(num_models);
  ParallelFor(num_models, threads, [&](std::size_t i) {
    histograms[i] = *codebook->Encode(models[i].data(), models[i].size() / kDim, kDim);
  });
  const double seconds = Now() - t, cpu_seconds = CpuSeconds() - cpu;
  std::printf(
      "encode %zu models (%zu descriptors) on %d threads: %.1f s wall, %.1f s CPU (%.1f ms CPU "
      "per model)\n",
      num_models,
      total,
      threads,
      seconds,
      cpu_seconds,
      1000.0 * cpu_seconds / num_models);

  const std::size_t num_exact =
      std::min(num_models, static_cast<std::size_t>(absl::GetFlag(FLAGS_exact_models)));
  if (num_exact == 0) return 0;
  absl::StatusOr<Codebook> exact = Codebook::FromCentroids(codebook->centroids(), kDim);
  std::size_t same = 0, count = 0;
  double l1 = 0.0;
  const double exact_cpu = CpuSeconds();
  std::vector<std::vector<uint32_t>> exact_labels(num_exact);
  ParallelFor(num_exact, threads, [&](std::size_t i) {
    exact_labels[i] = *exact->NearestCentroids(models[i].data(), models[i].size() / kDim);
  });
  const double exact_seconds = CpuSeconds() - exact_cpu;
  for (std::size_t i = 0; i < num_exact; ++i) {
    const std::vector<uint32_t> labels =
        *codebook->NearestCentroids(models[i].data(), models[i].size() / kDim);
    const std::vector<float> h = *exact->Encode(models[i].data(), models[i].size() / kDim, kDim);
    for (std::size_t j = 0; j < labels.size(); ++j) same += labels[j] == exact_labels[i][j];
    count += labels.size();
    for (std::size_t w = 0; w < h.size(); ++w) l1 += std::abs(h[w] - histograms[i][w]);
  }
  std::printf(
      "  exact search on the first %zu models: %.1f ms CPU per model (%.0f s CPU for all %zu); "
      "label agreement %.4f, mean histogram L1 difference %.4f\n",
      num_exact,
      1000.0 * exact_seconds / num_exact,
      exact_seconds / num_exact * num_models,
      num_models,
      static_cast<double>(same) / count,
      l1 / num_exact);
  return 0;
}

int Libraries() {
  absl::StatusOr<Codebook> codebook = ReadCodebook();
  if (!codebook.ok()) {
    std::cerr << codebook.status() << "\n";
    return 1;
  }
  const int threads = absl::GetFlag(FLAGS_threads);
  const std::size_t n = static_cast<std::size_t>(absl::GetFlag(FLAGS_agreement_sample));
  SiftLikeGenerator gen(200000, 42);
  const std::vector<uint8_t> data = gen.Sample(n);
  const std::vector<float>& c = codebook->centroids();
  const std::size_t v = codebook->size();
  std::printf("nearest-centroid search of %zu points against V = %zu, %d threads\n", n, v, threads);
  for (int probes : ParseList(absl::GetFlag(FLAGS_probes_list))) {
    MeasureAgreement(c, data.data(), n, ApproximateSearchParams::Resolve(0, probes, v), threads);
  }
#ifdef MESHSEEK_HAVE_FAISS
  omp_set_num_threads(threads);
  std::vector<float> x(data.begin(), data.end());
  std::vector<uint32_t> exact(n);
  NearestCentroidIndex(c.data(), v, kDim).Search(data.data(), n, threads, exact.data(), nullptr);
  auto report = [&](const char* what, double build, double search, const std::vector<int64_t>& l) {
    std::size_t same = 0;
    for (std::size_t i = 0; i < n; ++i) same += static_cast<int64_t>(exact[i]) == l[i];
    std::printf("  faiss %s (CPU seconds): build %.2f s, search %.2f s, agreement %.4f\n",
                what,
                build,
                search,
                static_cast<double>(same) / n);
    std::fflush(stdout);
  };
  std::vector<float> dist(n);
  std::vector<int64_t> labels(n);
  {
    faiss::IndexFlatL2 flat(kDim);
    flat.add(v, c.data());
    const double t = CpuSeconds();
    flat.search(n, x.data(), 1, dist.data(), labels.data());
    report("IndexFlatL2 (exact, BLAS sgemm)", 0.0, CpuSeconds() - t, labels);
  }
  for (int probes : ParseList(absl::GetFlag(FLAGS_probes_list))) {
    const ApproximateSearchParams p = ApproximateSearchParams::Resolve(0, probes, v);
    faiss::IndexFlatL2 quantizer(kDim);
    faiss::IndexIVFFlat ivf(&quantizer, kDim, p.groups);
    double t = CpuSeconds();
    ivf.train(v, c.data());
    ivf.add(v, c.data());
    const double build = CpuSeconds() - t;
    ivf.nprobe = p.probes;
    t = CpuSeconds();
    ivf.search(n, x.data(), 1, dist.data(), labels.data());
    const std::string what = "IndexIVFFlat (" + std::to_string(p.groups) + " lists, nprobe " +
                             std::to_string(p.probes) + ")";
    report(what.c_str(), build, CpuSeconds() - t, labels);
  }
  {
    faiss::IndexHNSWFlat hnsw(kDim, 32);
    hnsw.hnsw.efConstruction = 40;
    double t = CpuSeconds();
    hnsw.add(v, c.data());
    const double build = CpuSeconds() - t;
    for (int ef : {16, 32, 64, 128}) {
      hnsw.hnsw.efSearch = ef;
      t = CpuSeconds();
      hnsw.search(n, x.data(), 1, dist.data(), labels.data());
      const std::string what = "IndexHNSWFlat (M 32, efSearch " + std::to_string(ef) + ")";
      report(what.c_str(), build, CpuSeconds() - t, labels);
    }
  }
#else
  std::printf("  (built without Faiss: no library comparison)\n");
#endif
  return 0;
}

int Collection() {
  absl::StatusOr<std::vector<ManifestEntry>> models = ReadManifest(absl::GetFlag(FLAGS_manifest));
  if (!models.ok()) {
    std::cerr << models.status() << "\n";
    return 1;
  }
  RetrievalPipelineOptions options;
  options.num_threads = absl::GetFlag(FLAGS_threads);
  options.kmeans.num_centroids = absl::GetFlag(FLAGS_vocabulary);
  options.kmeans.seed = absl::GetFlag(FLAGS_seed);
  double t = Now();
  absl::StatusOr<std::vector<LocalFeatures>> features = ExtractCollection(*models, options);
  if (!features.ok()) {
    std::cerr << features.status() << "\n";
    return 1;
  }
  std::size_t total = 0;
  for (const LocalFeatures& f : *features) total += f.size();
  std::printf("%zu models, %zu DLD-SIFT descriptors, extracted in %.1f s\n",
              models->size(),
              total,
              Now() - t);
  std::vector<uint8_t> descriptors;
  descriptors.reserve(total * kDim);
  for (const LocalFeatures& f : *features) {
    descriptors.insert(descriptors.end(), f.descriptors.begin(), f.descriptors.end());
  }
  std::vector<std::string> labels;
  for (const ManifestEntry& m : *models) labels.push_back(m.label);

  std::vector<std::pair<std::string, KMeansOptions>> variants;
  for (int iterations : ParseList(absl::GetFlag(FLAGS_iterations_list))) {
    KMeansOptions base = options.kmeans;
    base.max_iterations = iterations;
    const std::string it = ", " + std::to_string(iterations) + " it max";
    KMeansOptions exact = base;
    exact.assignment = KMeansOptions::Assignment::kExact;
    exact.seeding = KMeansOptions::Seeding::kKMeansPlusPlus;
    variants.emplace_back("exact, k-means++" + it, exact);
    for (int probes : ParseList(absl::GetFlag(FLAGS_probes_list))) {
      KMeansOptions approx = base;
      approx.assignment = KMeansOptions::Assignment::kApproximate;
      approx.approximate_probes = probes;
      approx.seeding = KMeansOptions::Seeding::kRandomDistinct;
      variants.emplace_back("approx " + std::to_string(probes) + " probes, random" + it, approx);
      approx.seeding = KMeansOptions::Seeding::kKMeansPlusPlus;
      variants.emplace_back("approx " + std::to_string(probes) + " probes, k-means++" + it,
                            approx);
    }
  }
  for (auto& [name, kmeans] : variants) {
    kmeans.num_threads = options.num_threads;
    KMeansReport report;
    const double cpu = CpuSeconds();
    absl::StatusOr<Codebook> codebook =
        Codebook::Train(descriptors.data(), total, kDim, kmeans, &report);
    const double train_seconds = CpuSeconds() - cpu;
    if (!codebook.ok()) {
      std::cerr << codebook.status() << "\n";
      return 1;
    }
    const double encode_cpu = CpuSeconds();
    absl::StatusOr<std::vector<std::vector<float>>> histograms =
        EncodeCollection(*codebook, *features, options);
    const double encode_seconds = CpuSeconds() - encode_cpu;
    absl::StatusOr<std::vector<float>> distances = RankCollection(*histograms, options);
    absl::StatusOr<RetrievalMetrics> metrics =
        EvaluateRetrieval(labels, *distances, options.num_threads);
    if (!metrics.ok()) {
      std::cerr << metrics.status() << "\n";
      return 1;
    }
    // The exact objective of the final centroids over every descriptor.
    std::vector<uint32_t> nearest(total);
    std::vector<float> d2(total);
    NearestCentroidIndex(codebook->centroids().data(), codebook->size(), kDim)
        .Search(descriptors.data(), total, options.num_threads, nearest.data(), d2.data());
    double objective = 0.0;
    for (float d : d2) objective += d;
    objective /= total;
    std::printf(
        "V = %zu, %-44s CPU s: train %6.1f (%2d it), encode %5.1f; exact objective %.1f, "
        "FT %.1f, NN %.1f (micro, percent)\n",
        codebook->size(),
        name.c_str(),
        train_seconds,
        report.iterations,
        encode_seconds,
        objective,
        100.0 * metrics->micro.first_tier,
        100.0 * metrics->micro.nn);
    std::fflush(stdout);
  }
  return 0;
}

}  // namespace
}  // namespace meshseek

int main(int argc, char** argv) {
  absl::ParseCommandLine(argc, argv);
  const std::string experiment = absl::GetFlag(FLAGS_experiment);
  if (experiment == "train") return meshseek::Train();
  if (experiment == "encode") return meshseek::Encode();
  if (experiment == "libraries") return meshseek::Libraries();
  if (experiment == "collection") return meshseek::Collection();
  std::cerr << "unknown --experiment=" << experiment << "\n";
  return 2;
}
