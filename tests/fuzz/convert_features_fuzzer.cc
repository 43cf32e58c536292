// FeaturesFromProto on a LocalFeatures message parsed from the bytes (what the
// codebook service receives); accepted features are consistent and round-trip.
#include <cstdint>
#include <cstdlib>

#include "common/wire/convert.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  meshseek::v1::LocalFeatures message;
  if (!message.ParseFromArray(data, static_cast<int>(size))) return 0;
  const absl::StatusOr<meshseek::LocalFeatures> features =
      meshseek::wire::FeaturesFromProto(message);
  if (!features.ok()) return 0;
  if (features->descriptors.size() != features->size() * features->dimension) std::abort();
  meshseek::v1::LocalFeatures back;
  meshseek::wire::FeaturesToProto(*features, &back);
  const absl::StatusOr<meshseek::LocalFeatures> again = meshseek::wire::FeaturesFromProto(back);
  if (!again.ok() || again->size() != features->size()) std::abort();
  return 0;
}
