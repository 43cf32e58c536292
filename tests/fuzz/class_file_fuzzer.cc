// The PSB class-file reader on arbitrary text; a file it accepts must also be
// one WritePsbClassFile's checks accept (the flattened views agree).
#include <cstdint>
#include <cstdlib>
#include <string>

#include "absl/strings/match.h"
#include "common/eval/class_file.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const absl::string_view text(reinterpret_cast<const char*>(data), size);
  const auto file = meshseek::ParsePsbClassFile(text, "fuzz.cla");
  if (!file.ok()) {
    if (!absl::StartsWith(file.status().message(), "fuzz.cla:")) std::abort();
    return 0;
  }
  std::size_t models = 0;
  for (const auto& cls : file->classes) models += cls.model_ids.size();
  if (models != file->model_ids.size() || models != file->labels.size()) std::abort();
  return 0;
}
