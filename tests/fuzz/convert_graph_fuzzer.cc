// GraphFromProto on a PointGraph message parsed from the bytes (what the
// extract service receives from resample); accepted graphs round-trip.
#include <cstdint>
#include <cstdlib>

#include "common/wire/convert.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  meshseek::v1::PointGraph message;
  if (!message.ParseFromArray(data, static_cast<int>(size))) return 0;
  const absl::StatusOr<meshseek::PointGraph> graph = meshseek::wire::GraphFromProto(message);
  if (!graph.ok()) return 0;
  meshseek::v1::PointGraph back;
  meshseek::wire::GraphToProto(*graph, &back);
  const absl::StatusOr<meshseek::PointGraph> again = meshseek::wire::GraphFromProto(back);
  if (!again.ok() || again->neighbors != graph->neighbors) std::abort();
  return 0;
}
