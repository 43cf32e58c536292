// SparseHistogramFromProto on a SparseHistogram message parsed from the bytes
// (what the index service receives); accepted histograms round-trip.
#include <cstdint>
#include <cstdlib>

#include "common/wire/convert.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  meshseek::v1::SparseHistogram message;
  if (!message.ParseFromArray(data, static_cast<int>(size))) return 0;
  const absl::StatusOr<meshseek::SparseHistogram> histogram =
      meshseek::wire::SparseHistogramFromProto(message, "model 'fuzz'");
  if (!histogram.ok()) {
    if (histogram.status().message().find("model 'fuzz'") == absl::string_view::npos) {
      std::abort();
    }
    return 0;
  }
  meshseek::v1::SparseHistogram back;
  meshseek::wire::SparseHistogramToProto(*histogram, &back);
  const absl::StatusOr<meshseek::SparseHistogram> again =
      meshseek::wire::SparseHistogramFromProto(back, "model 'fuzz'");
  if (!again.ok() || again->words != histogram->words) std::abort();
  return 0;
}
