// PipelineOptionsFromParams on a PipelineParams message parsed from the bytes
// (what CreateCollection and Extract receive): the options it returns are
// valid ones.
#include <cstdint>
#include <cstdlib>

#include "common/wire/convert.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  meshseek::v1::PipelineParams message;
  if (!message.ParseFromArray(data, static_cast<int>(size))) return 0;
  const absl::StatusOr<meshseek::RetrievalPipelineOptions> options =
      meshseek::wire::PipelineOptionsFromParams(message);
  if (options.ok() && !options->Validate().ok()) std::abort();
  return 0;
}
