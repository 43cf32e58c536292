// What a client command prints: text for people (the default) or JSON for
// programs (--format json). Scripts and tests read the JSON, never the text,
// whose wording may change (tests/deploy_test.sh once failed on a reworded
// status line).
//
// JSON is one document on stdout per command. A message of the API is written
// in protobuf's canonical JSON mapping with the proto's own field names
// (snake_case), every field present even when zero or empty, enums by name;
// as that mapping prescribes, 64-bit integers (model counts) are JSON strings.
// `eval` prints the document it writes as metrics.json.
#ifndef MESHSEEK_CLI_OUTPUT_FORMAT_H_
#define MESHSEEK_CLI_OUTPUT_FORMAT_H_

#include <string>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "google/protobuf/message.h"

namespace meshseek::cli {

enum class OutputFormat { kText, kJson };

/// The format named by --format: "text" or "json"; InvalidArgument otherwise.
absl::StatusOr<OutputFormat> OutputFormatFromName(absl::string_view name);

/// `message` in the canonical JSON mapping described above, on one line.
std::string ProtoToJson(const google::protobuf::Message& message);

}  // namespace meshseek::cli

#endif  // MESHSEEK_CLI_OUTPUT_FORMAT_H_
