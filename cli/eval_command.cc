#include <cstdio>
#include <string>

#include "absl/flags/flag.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "cli/commands.h"
#include "cli/output_format.h"
#include "cli/pipeline_flags.h"
#include "common/base/parallel.h"
#include "common/base/status_macros.h"
#include "common/pipeline/collection_evaluation.h"

ABSL_FLAG(std::string,
          manifest,
          "",
          "eval: CSV manifest with columns id,class,path (paths relative to it)");
ABSL_FLAG(std::string, out, "", "output folder");

namespace meshseek::cli {

absl::Status RunEval() {
  const std::string manifest_path = absl::GetFlag(FLAGS_manifest);
  const std::string out_dir = absl::GetFlag(FLAGS_out);
  if (manifest_path.empty()) return absl::InvalidArgumentError("eval needs --manifest FILE");
  if (out_dir.empty()) return absl::InvalidArgumentError("eval needs --out DIR");

  MESHSEEK_ASSIGN_OR_RETURN(const OutputFormat format, OutputFormatFromFlags());
  MESHSEEK_ASSIGN_OR_RETURN(CollectionOptions options, CollectionOptionsFromFlags());
  MESHSEEK_ASSIGN_OR_RETURN(const std::vector<ManifestEntry> models, ReadManifest(manifest_path));
  std::fprintf(stderr,
               "meshseek eval: %zu models from %s, method %s, %d threads\n",
               models.size(),
               manifest_path.c_str(),
               options.MethodName().c_str(),
               ResolveThreadCount(options.num_threads()));
  MESHSEEK_ASSIGN_OR_RETURN(const CollectionEvaluation evaluation,
                            EvalInProcess()
                                ? EvaluateCollection(models, options)
                                : EvaluateThroughServices(models, &options, manifest_path));
  MESHSEEK_RETURN_IF_ERROR(WriteEvaluation(evaluation, options, out_dir));
  if (format == OutputFormat::kJson) {
    std::printf("%s\n", EvaluationMetricsJson(evaluation, options).Dump().c_str());
    return absl::OkStatus();
  }

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
  std::printf(EvalInProcess()
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
  return absl::OkStatus();
}

}  // namespace meshseek::cli
