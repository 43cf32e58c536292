#include <cstdio>
#include <string>

#include "absl/status/status.h"
#include "cli/commands.h"
#include "common/base/status_macros.h"
#include "common/synth/synthetic_benchmark.h"

namespace meshseek::cli {

absl::Status RunSynth(const CliFlags& flags) {
  const std::string& out_dir = flags.out;
  if (out_dir.empty()) return absl::InvalidArgumentError("synth needs --out DIR");
  SyntheticBenchmarkOptions options;
  options.models_per_class = flags.models_per_class;
  // The synthetic benchmark has its own default seed; --seed (the pipeline
  // parameter, default 0) changes it only when given.
  MESHSEEK_ASSIGN_OR_RETURN(const RetrievalPipelineOptions pipeline, flags::PipelineOptionsFromFlags(flags.params));
  if (pipeline.kmeans.seed != 0) options.seed = pipeline.kmeans.seed;
  MESHSEEK_RETURN_IF_ERROR(options.Validate());
  MESHSEEK_RETURN_IF_ERROR(GenerateSyntheticBenchmark(options, out_dir));
  std::printf("wrote the synthetic benchmark (%d models per class, seed %llu) to %s\n",
              options.models_per_class,
              static_cast<unsigned long long>(options.seed),
              out_dir.c_str());
  return absl::OkStatus();
}

}  // namespace meshseek::cli
