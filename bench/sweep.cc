// Parameter sweeps on a labelled collection, for choosing defaults on the
// development sets (McGill articulated, PSB train) and for the E plot.
//
//   sweep --manifest FILE --scales 0.1,0.2,0.3 --vocabularies 500,1000,2000
//         [--epsilons 1e-6,1e-10] [--csv OUT] [--tag TEXT] [any pipeline flag of
//         `meshseek eval`: --orientation, --frame_samples, --seed, ...]
//
// Extracts once per scale E and reuses the features for every vocabulary
// size V and KL epsilon; prints one row per (E, V, epsilon) and appends it to
// --csv. Methods without a scale knob (bfdsift, lsf) ignore --scales.
// --features_cache FILE keeps the extracted features of a run (one scale) in
// FILE and reads them back on the next run instead of extracting: sweeps of
// the codebook and histogram stages then cost no extraction. The file is not
// checked against the extraction flags: one file per extraction setting.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "absl/flags/flag.h"
#include "absl/flags/parse.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_split.h"
#include "common/flags/pipeline_flags.h"
#include "common/eval/retrieval_metrics.h"
#include "common/pipeline/retrieval_pipeline.h"

ABSL_FLAG(std::string, manifest, "", "CSV manifest id,class,path");
ABSL_FLAG(std::string,
          scales,
          "",
          "comma-separated scales: E for --method dld, C (scale factor) for ld and rld "
          "(default: the method's shipped one)");
ABSL_FLAG(std::string,
          vocabularies,
          "",
          "comma-separated codebook sizes V (default: the shipped one)");
ABSL_FLAG(std::string, epsilons, "", "comma-separated KL epsilons (default: the shipped one)");
ABSL_FLAG(std::string, csv, "", "append result rows to this CSV file");
ABSL_FLAG(std::string, tag, "", "free text copied into the CSV rows");
ABSL_FLAG(std::string,
          features_cache,
          "",
          "read the features from this file if it exists, else extract and write them there");
ABSL_FLAG(std::string,
          weightings,
          "none",
          "comma-separated histogram weightings none|idf|pow0.5|idfpow0.5 (histogram_weighting.h)");
ABSL_FLAG(std::string, distances, "kl", "experimental: comma-separated kl|l1|l2|hell");
ABSL_FLAG(std::string,
          keep_levels,
          "",
          "comma-separated keypoint levels to keep (BF-DSIFT: patch scale index), all if empty; "
          "one extraction at several scales then measures every subset");

namespace {

template <typename T>
std::vector<T> ParseList(const std::string& text) {
  std::vector<T> values;
  for (absl::string_view part : absl::StrSplit(text, ',', absl::SkipEmpty())) {
    double v;
    if (!absl::SimpleAtod(part, &v)) {
      std::fprintf(stderr, "bad number '%s'\n", std::string(part).c_str());
      std::exit(2);
    }
    values.push_back(static_cast<T>(v));
  }
  return values;
}

// The cache file: "MSFC", model count, then per model the keypoint count,
// the descriptor dimension, the keypoints and the descriptors, raw.
bool WriteFeatures(const std::string& path, const std::vector<meshseek::LocalFeatures>& all) {
  std::ofstream out(path, std::ios::binary);
  const auto put = [&](const void* p, std::size_t n) {
    out.write(static_cast<const char*>(p), static_cast<std::streamsize>(n));
  };
  const uint64_t count = all.size();
  put("MSFC", 4);
  put(&count, sizeof count);
  for (const meshseek::LocalFeatures& f : all) {
    const uint64_t header[2] = {f.keypoints.size(), f.dimension};
    put(header, sizeof header);
    put(f.keypoints.data(), f.keypoints.size() * sizeof(meshseek::Keypoint));
    put(f.descriptors.data(), f.descriptors.size());
  }
  return static_cast<bool>(out);
}

bool ReadFeatures(const std::string& path, std::vector<meshseek::LocalFeatures>* all) {
  std::ifstream in(path, std::ios::binary);
  const auto get = [&](void* p, std::size_t n) {
    return static_cast<bool>(in.read(static_cast<char*>(p), static_cast<std::streamsize>(n)));
  };
  char magic[4];
  uint64_t count = 0;
  if (!get(magic, 4) || std::string(magic, 4) != "MSFC" || !get(&count, sizeof count)) return false;
  all->resize(count);
  for (meshseek::LocalFeatures& f : *all) {
    uint64_t header[2];
    if (!get(header, sizeof header) || header[0] > (1u << 24) ||
        header[1] > meshseek::kMaxDescriptorDimension)
      return false;
    f.keypoints.resize(header[0]);
    f.dimension = header[1];
    f.descriptors.resize(header[0] * header[1]);
    if (!get(f.keypoints.data(), f.keypoints.size() * sizeof(meshseek::Keypoint)) ||
        !get(f.descriptors.data(), f.descriptors.size()))
      return false;
  }
  return true;
}

// A --weightings entry as the shipped HistogramWeighting: "none", "idf",
// "pow<a>" (power a), "idfpow<a>" (both).
meshseek::HistogramWeighting ParseWeighting(const std::string& mode) {
  meshseek::HistogramWeighting w;
  w.idf = mode.rfind("idf", 0) == 0;
  const std::size_t at = mode.find("pow");
  if (at != std::string::npos) w.power = std::stod(mode.substr(at + 3));
  return w;
}

// Experimental distances on dense histograms: "l1", "l2" (of L2-normalised
// vectors, i.e. cosine), "hell" (L2 of square roots).
std::vector<float> DenseDistances(const std::string& kind, std::vector<std::vector<float>> hs) {
  const std::size_t n = hs.size();
  for (auto& h : hs) {
    if (kind == "hell") {
      for (float& x : h) x = std::sqrt(x);
    } else if (kind == "l2") {
      double s = 0;
      for (float x : h) s += double(x) * x;
      s = std::sqrt(s);
      if (s > 0)
        for (float& x : h) x = static_cast<float>(x / s);
    }
  }
  std::vector<float> d(n * n, 0);
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i + 1; j < n; ++j) {
      double s = 0;
      for (std::size_t k = 0; k < hs[i].size(); ++k) {
        const double t = double(hs[i][k]) - hs[j][k];
        s += kind == "l1" ? std::abs(t) : t * t;
      }
      d[i * n + j] = d[j * n + i] = static_cast<float>(s);
    }
  }
  return d;
}

}  // namespace

int main(int argc, char** argv) {
  const meshseek::flags::CommandLine line =
      meshseek::flags::ParseCommandLineWithParams(argc, argv, "");
  cv::setNumThreads(0);
  using namespace meshseek;
  auto models = ReadManifest(absl::GetFlag(FLAGS_manifest));
  if (!models.ok()) {
    std::fprintf(stderr, "%s\n", models.status().ToString().c_str());
    return 1;
  }
  auto parsed = flags::PipelineOptionsFromFlags(line.params);
  if (!parsed.ok()) {
    std::fprintf(stderr, "%s\n", parsed.status().ToString().c_str());
    return 2;
  }
  RetrievalPipelineOptions options = *parsed;
  std::vector<double> epsilons = ParseList<double>(absl::GetFlag(FLAGS_epsilons));
  if (epsilons.empty()) epsilons.push_back(options.kl.epsilon);
  std::vector<std::string> labels;
  for (const auto& m : *models) labels.push_back(m.label);

  std::printf(
      "tag,scale,V,epsilon,RP_excl_micro,RP_excl_macro,RP_incl_micro,NN_micro,ST_micro,DCG_micro,"
      "extract_s\n");
  std::vector<double> scales = ParseList<double>(absl::GetFlag(FLAGS_scales));
  const FeatureMethod method = options.extractor.method;
  const bool has_scale = method == FeatureMethod::kDldSift || method == FeatureMethod::kLdSift ||
                         method == FeatureMethod::kRldSift;
  if (!has_scale) scales = {0};
  if (scales.empty()) {
    scales.push_back(method == FeatureMethod::kDldSift ? options.extractor.dld.scale
                     : method == FeatureMethod::kLdSift
                         ? options.extractor.ld.scale_space.scale_factor
                         : options.extractor.rld.scale_space.scale_factor);
  }
  const std::string cache = absl::GetFlag(FLAGS_features_cache);
  if (!cache.empty() && scales.size() != 1) {
    std::fprintf(stderr, "--features_cache takes one scale\n");
    return 2;
  }
  for (double scale : scales) {
    // The method's scale knob: E for DLD-SIFT, C for the scale-space methods.
    if (has_scale) {
      options.extractor.dld.scale = scale;
      options.extractor.ld.scale_space.scale_factor = scale;
      options.extractor.rld.scale_space.scale_factor = scale;
    }
    const auto start = std::chrono::steady_clock::now();
    absl::StatusOr<std::vector<LocalFeatures>> features;
    if (!cache.empty() && std::ifstream(cache).good()) {
      features.emplace();
      if (!ReadFeatures(cache, &*features)) {
        std::fprintf(stderr, "cannot read features cache %s\n", cache.c_str());
        return 1;
      }
    } else {
      features = ExtractCollection(*models, options);
      if (!features.ok()) {
        std::fprintf(stderr, "%s\n", features.status().ToString().c_str());
        return 1;
      }
      if (!cache.empty() && !WriteFeatures(cache, *features)) {
        std::fprintf(stderr, "cannot write features cache %s\n", cache.c_str());
        return 1;
      }
    }
    const std::vector<int> keep = ParseList<int>(absl::GetFlag(FLAGS_keep_levels));
    if (!keep.empty()) {
      for (LocalFeatures& f : *features) {
        LocalFeatures kept;
        kept.dimension = f.dimension;
        for (std::size_t i = 0; i < f.size(); ++i) {
          if (std::find(keep.begin(), keep.end(), f.keypoints[i].level) == keep.end()) continue;
          kept.keypoints.push_back(f.keypoints[i]);
          kept.descriptors.insert(
              kept.descriptors.end(), f.descriptor(i), f.descriptor(i) + f.dimension);
        }
        f = std::move(kept);
      }
    }
    const double extract_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::vector<int> vocabularies = ParseList<int>(absl::GetFlag(FLAGS_vocabularies));
    if (vocabularies.empty()) vocabularies.push_back(options.kmeans.num_centroids);
    for (int v : vocabularies) {
      options.kmeans.num_centroids = v;
      auto codebook = TrainCollectionCodebook(*features, options);
      if (!codebook.ok()) {
        std::fprintf(stderr, "%s\n", codebook.status().ToString().c_str());
        return 1;
      }
      options.weighting = {};  // each --weightings entry below
      const auto encoded = EncodeCollection(*codebook, *features, options);
      for (absl::string_view weighting : absl::StrSplit(absl::GetFlag(FLAGS_weightings), ',')) {
        for (absl::string_view distance : absl::StrSplit(absl::GetFlag(FLAGS_distances), ',')) {
          for (double eps : distance == "kl" ? epsilons : std::vector<double>{0}) {
            std::vector<std::vector<float>> histograms = *encoded;
            if (absl::Status s =
                    WeightCollection(ParseWeighting(std::string(weighting)), &histograms);
                !s.ok()) {
              std::fprintf(stderr, "%s\n", s.ToString().c_str());
              return 1;
            }
            std::vector<float> matrix;
            if (distance == "kl") {
              options.kl.epsilon = eps;
              matrix = *RankCollection(histograms, options);
            } else {
              matrix = DenseDistances(std::string(distance), histograms);
            }
            auto metrics = EvaluateRetrieval(labels, matrix, options.num_threads);
            const std::string row =
                absl::StrFormat("%s %s %s,%g,%d,%g,%.2f,%.2f,%.2f,%.2f,%.2f,%.2f,%.1f",
                                absl::GetFlag(FLAGS_tag),
                                weighting,
                                distance,
                                scale,
                                v,
                                eps,
                                100 * metrics->micro.rp_excl,
                                100 * metrics->macro.rp_excl,
                                100 * metrics->micro.rp_incl,
                                100 * metrics->micro.nn,
                                100 * metrics->micro.second_tier,
                                100 * metrics->micro.dcg,
                                extract_s);
            std::printf("%s\n", row.c_str());
            std::fflush(stdout);
            if (!absl::GetFlag(FLAGS_csv).empty())
              std::ofstream(absl::GetFlag(FLAGS_csv), std::ios::app) << row << "\n";
          }
        }
      }
    }
  }
  return 0;
}
