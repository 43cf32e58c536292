// meshseek eval: a labelled collection ingested, its codebooks trained, every
// pair ranked and the ranking evaluated, either in this process
// (--server in-process, the benchmark reference) or through the services
// (an embedded stack or --server), the paper's protocol either way.
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_replace.h"
#include "absl/time/clock.h"
#include "cli/commands.h"
#include "cli/coordinator_client.h"
#include "cli/output_format.h"
#include "common/base/hash.h"
#include "common/base/parallel.h"
#include "common/base/status_macros.h"
#include "common/pipeline/collection_evaluation.h"
#include "common/rpc/status.h"
#include "common/wire/convert.h"

namespace meshseek::cli {
namespace {

constexpr char kInProcess[] = "in-process";

// The collection an eval names none of: after the manifest's folder, the
// method and a hash of the canonical parameters (every one of the
// collection, by name), so that evaluating again reuses the extracted models.
std::string EvalCollectionName(const CollectionOptions& options, const std::string& manifest_path) {
  v1::PipelineParams canonical;
  wire::CollectionParamsToProto(options, &canonical);
  std::string folder = std::filesystem::absolute(manifest_path).parent_path().filename().string();
  for (char& c : folder) {
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_') c = '_';
  }
  return absl::StrCat(
      folder.empty() ? "eval" : folder,
      "-",
      absl::StrReplaceAll(options.MethodName(), {{"+", "_"}}),
      "-",
      absl::Hex(Fnv1a64(canonical.SerializeAsString(), kFnv1a64OffsetBasis) & 0xffffffffu,
                absl::kZeroPad8));
}

// Every row of the collection's distance matrix (the Evaluate stream) into
// `evaluation` (distances in manifest order, features per model and method);
// retried whole while the coordinator is unreachable.
absl::Status ReadDistanceRows(CoordinatorClient& client,
                              const std::string& collection,
                              CollectionEvaluation* evaluation) {
  const std::size_t n = evaluation->models.size();
  std::map<std::string, std::size_t> position;
  for (std::size_t i = 0; i < n; ++i) position[evaluation->models[i].id] = i;
  return rpc::RetryTransient(
      [&]() -> absl::Status {
        grpc::ClientContext context;
        rpc::SetDeadline(&context, absl::Minutes(30));
        v1::EvaluateRequest request;
        request.set_collection(collection);
        auto reader = client.stub()->Evaluate(&context, request);
        v1::EvaluateRow row;
        std::vector<std::string> row_ids;
        std::vector<std::pair<std::size_t, std::vector<float>>> pending;
        std::size_t rows = 0;
        while (reader->Read(&row)) {
          auto it = position.find(row.model_id());
          if (it == position.end() || row.distances_size() != static_cast<int>(n)) {
            context.TryCancel();
            reader->Finish();
            return absl::FailedPreconditionError(absl::StrCat(
                "collection '", collection, "' holds model ", row.model_id(),
                " that is not in the manifest or has another size; use another --collection"));
          }
          row_ids.push_back(row.model_id());
          pending.emplace_back(it->second, std::vector<float>(row.distances().begin(), row.distances().end()));
          // One count per method (a row of a collection of one method may
          // carry only `features`).
          for (std::size_t m = 0; m < evaluation->methods.size(); ++m) {
            evaluation->methods[m].features_per_model[it->second] =
                m < static_cast<std::size_t>(row.method_features_size())
                    ? row.method_features(static_cast<int>(m))
                    : row.features();
          }
          ++rows;
        }
        MESHSEEK_RETURN_IF_ERROR(rpc::FromGrpcStatus(reader->Finish()));
        if (rows != n) {
          return absl::FailedPreconditionError(absl::StrCat(
              "collection '", collection, "' has ", rows, " models, the manifest ", n));
        }
        // Row r's columns are in the collection's order (row_ids).
        for (auto& [i, distances] : pending) {
          for (std::size_t c = 0; c < n; ++c) {
            evaluation->distances[i * n + position[row_ids[c]]] = distances[c];
          }
        }
        return absl::OkStatus();
      },
      client.retry());
}

// The eval through the coordinator: the models ingested into --collection
// (or the collection EvalCollectionName names), built when anything changed
// since its build, and its distance matrix read back. An existing collection
// keeps the options it was made with: they replace `options` (run options
// kept), so that the metrics say what was measured.
absl::StatusOr<CollectionEvaluation> EvaluateThroughServices(const CliFlags& flags,
                                                             const std::vector<ManifestEntry>& models,
                                                             CollectionOptions* options) {
  const auto start = absl::Now();
  MESHSEEK_ASSIGN_OR_RETURN(auto client, CoordinatorClient::Open(flags.client));
  const std::string collection =
      flags.collection.empty() ? EvalCollectionName(*options, flags.manifest) : flags.collection;
  MESHSEEK_RETURN_IF_ERROR(client->EnsureCollection(collection, flags.params));
  MESHSEEK_RETURN_IF_ERROR(client->Ingest(collection, ModelsOfManifest(models)));
  CollectionEvaluation evaluation;
  evaluation.timings.extract_seconds = absl::ToDoubleSeconds(absl::Now() - start);
  MESHSEEK_ASSIGN_OR_RETURN(const v1::Collection info, client->GetCollection(collection));
  const auto build_start = absl::Now();
  // The paper's protocol: codebooks trained on every model evaluated, so
  // models added live since the last build mean a build too.
  if (info.codebook_id().empty() || info.indexed() != info.models() ||
      info.added_since_build() > 0) {
    MESHSEEK_RETURN_IF_ERROR(client->Build(collection));
  }
  evaluation.timings.codebook_seconds = absl::ToDoubleSeconds(absl::Now() - build_start);
  const auto rank_start = absl::Now();
  MESHSEEK_ASSIGN_OR_RETURN(CollectionOptions stored,
                            wire::CollectionOptionsFromParams(info.params()));
  stored.SetRunOptions(options->num_threads(), options->show_progress());
  *options = stored;
  const std::size_t n = models.size();
  evaluation.models = models;
  evaluation.distances.assign(n * n, 0.0f);
  evaluation.methods.resize(stored.methods.size());
  for (std::size_t m = 0; m < stored.methods.size(); ++m) {
    MethodEvaluation& method = evaluation.methods[m];
    method.method = stored.methods[m].extractor.method;
    method.features_per_model.assign(n, 0);
    method.codebook_size = FeatureMethodInfoOf(method.method).kind == DescriptorKind::kGlobal
                               ? 0
                               : stored.methods[m].kmeans.num_centroids;
  }
  MESHSEEK_RETURN_IF_ERROR(ReadDistanceRows(*client, collection, &evaluation));
  for (MethodEvaluation& method : evaluation.methods) {
    for (std::size_t f : method.features_per_model) method.models_without_features += f == 0;
  }
  std::vector<std::string> labels;
  for (const ManifestEntry& m : models) labels.push_back(m.label);
  MESHSEEK_ASSIGN_OR_RETURN(evaluation.metrics,
                            EvaluateRetrieval(labels, evaluation.distances, stored.num_threads()));
  evaluation.timings.rank_seconds = absl::ToDoubleSeconds(absl::Now() - rank_start);
  evaluation.timings.total_seconds = absl::ToDoubleSeconds(absl::Now() - start);
  std::fprintf(stderr, "eval: collection '%s'\n", collection.c_str());
  return evaluation;
}

void PrintEvaluation(const CollectionEvaluation& evaluation,
                     const CollectionOptions& options,
                     bool in_process,
                     const std::string& out_dir) {
  const StageTimings& t = evaluation.timings;
  std::printf("%s", FormatMetricsTable(evaluation.metrics).c_str());
  std::printf("R-precision (query excluded = first tier): %.1f %% micro, %.1f %% macro\n",
              100 * evaluation.metrics.micro.rp_excl,
              100 * evaluation.metrics.macro.rp_excl);
  std::vector<std::string> signatures;
  for (const MethodEvaluation& m : evaluation.methods) {
    signatures.push_back(
        m.codebook_size > 0
            ? absl::StrCat(FeatureMethodName(m.method), " codebook V = ", m.codebook_size)
            : absl::StrCat(FeatureMethodName(m.method), " global descriptors"));
  }
  std::string signature = absl::StrJoin(signatures, ", ");
  if (options.fused()) absl::StrAppend(&signature, ", fused");
  if (options.rerank.enabled()) absl::StrAppend(&signature, ", re-ranked");
  std::printf(in_process
                  ? "%zu models, %s; time %.1f s (extract %.1f, codebook %.1f, encode %.1f, "
                    "rank %.1f)\n"
                  : "%zu models, %s; time %.1f s (ingest+extract %.1f, codebook+encode+index "
                    "%.1f, -, distances+metrics %.1f)\n",
              evaluation.models.size(),
              signature.c_str(),
              t.total_seconds,
              t.extract_seconds,
              t.codebook_seconds,
              t.encode_seconds,
              t.rank_seconds);
  std::printf("wrote %s/distances.bin, %s/models.csv and %s/metrics.json\n",
              out_dir.c_str(),
              out_dir.c_str(),
              out_dir.c_str());
}

}  // namespace

absl::Status RunEval(const CliFlags& flags) {
  if (flags.manifest.empty()) return absl::InvalidArgumentError("eval needs --manifest FILE");
  if (flags.out.empty()) return absl::InvalidArgumentError("eval needs --out DIR");
  MESHSEEK_ASSIGN_OR_RETURN(CollectionOptions options, flags::CollectionOptionsFromFlags(flags.params));
  MESHSEEK_ASSIGN_OR_RETURN(const std::vector<ManifestEntry> models, ReadManifest(flags.manifest));
  std::fprintf(stderr,
               "meshseek eval: %zu models from %s, method %s, %d threads\n",
               models.size(),
               flags.manifest.c_str(),
               options.MethodName().c_str(),
               ResolveThreadCount(options.num_threads()));
  const bool in_process = flags.client.server == kInProcess;
  MESHSEEK_ASSIGN_OR_RETURN(const CollectionEvaluation evaluation,
                            in_process ? EvaluateCollection(models, options)
                                       : EvaluateThroughServices(flags, models, &options));
  MESHSEEK_RETURN_IF_ERROR(WriteEvaluation(evaluation, options, flags.out));
  if (flags.format == OutputFormat::kJson) {
    std::printf("%s\n", EvaluationMetricsJson(evaluation, options).Dump().c_str());
    return absl::OkStatus();
  }
  PrintEvaluation(evaluation, options, in_process, flags.out);
  return absl::OkStatus();
}

}  // namespace meshseek::cli
