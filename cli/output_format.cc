#include "cli/output_format.h"

#include "absl/strings/str_cat.h"
#include "google/protobuf/util/json_util.h"

namespace meshseek::cli {

absl::StatusOr<OutputFormat> OutputFormatFromName(absl::string_view format) {
  if (format == "text") return OutputFormat::kText;
  if (format == "json") return OutputFormat::kJson;
  return absl::InvalidArgumentError(
      absl::StrCat("--format '", format, "' is neither 'text' nor 'json'"));
}

std::string ProtoToJson(const google::protobuf::Message& message) {
  google::protobuf::util::JsonPrintOptions options;
  options.preserve_proto_field_names = true;
  options.always_print_primitive_fields = true;
  std::string json;
  // Serialising a valid in-memory message cannot fail (parsing can).
  (void)google::protobuf::util::MessageToJsonString(message, &json, options);
  return json;
}

}  // namespace meshseek::cli
