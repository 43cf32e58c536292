// Parameter sweeps on a labelled collection, for choosing defaults on the
// development sets (McGill articulated, PSB train) and for the E plot.
//
//   sweep --manifest FILE --scales 0.1,0.2,0.3 --vocabularies 500,1000,2000
//         [--epsilons 1e-6,1e-10] [--csv OUT] [--tag TEXT] [any pipeline flag of
//         `meshseek eval`: --orientation, --frame_samples, --seed, ...]
//
// Extracts once per scale E and reuses the features for every vocabulary
// size V and KL epsilon; prints one row per (E, V, epsilon) and appends it to
// --csv.
#include <chrono>
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
#include "cli/pipeline_flags.h"
#include "common/pipeline/retrieval_pipeline.h"

ABSL_FLAG(std::string, manifest, "", "CSV manifest id,class,path");
ABSL_FLAG(std::string,
          scales,
          "0.2",
          "comma-separated scales: E for --method dld, C (scale factor) for ld and rld");
ABSL_FLAG(std::string,
          vocabularies,
          "",
          "comma-separated codebook sizes V (default: the shipped one)");
ABSL_FLAG(std::string, epsilons, "", "comma-separated KL epsilons (default: the shipped one)");
ABSL_FLAG(std::string, csv, "", "append result rows to this CSV file");
ABSL_FLAG(std::string, tag, "", "free text copied into the CSV rows");

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

}  // namespace

int main(int argc, char** argv) {
  meshseek::cli::ParseCommandLineWithParams(argc, argv, "");
  cv::setNumThreads(0);
  using namespace meshseek;
  auto models = ReadManifest(absl::GetFlag(FLAGS_manifest));
  if (!models.ok()) {
    std::fprintf(stderr, "%s\n", models.status().ToString().c_str());
    return 1;
  }
  auto parsed = cli::PipelineOptionsFromFlags();
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
  if (scales.empty()) {
    switch (options.extractor.method) {
      case FeatureMethod::kDldSift:
        scales.push_back(options.extractor.dld.scale);
        break;
      case FeatureMethod::kLdSift:
        scales.push_back(options.extractor.ld.scale_space.scale_factor);
        break;
      case FeatureMethod::kRldSift:
        scales.push_back(options.extractor.rld.scale_space.scale_factor);
        break;
    }
  }
  for (double scale : scales) {
    // The method's scale knob: E for DLD-SIFT, C for the scale-space methods.
    options.extractor.dld.scale = scale;
    options.extractor.ld.scale_space.scale_factor = scale;
    options.extractor.rld.scale_space.scale_factor = scale;
    const auto start = std::chrono::steady_clock::now();
    auto features = ExtractCollection(*models, options);
    if (!features.ok()) {
      std::fprintf(stderr, "%s\n", features.status().ToString().c_str());
      return 1;
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
      auto histograms = EncodeCollection(*codebook, *features, options);
      for (double eps : epsilons) {
        options.kl.epsilon = eps;
        auto distances = RankCollection(*histograms, options);
        auto metrics = EvaluateRetrieval(labels, *distances, options.num_threads);
        const std::string row = absl::StrFormat("%s,%g,%d,%g,%.2f,%.2f,%.2f,%.2f,%.2f,%.2f,%.1f",
                                                absl::GetFlag(FLAGS_tag),
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
  return 0;
}
