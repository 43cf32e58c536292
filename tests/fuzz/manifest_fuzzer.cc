// The data-set manifest reader (CSV id,class,path) on arbitrary text.
#include <cstdint>
#include <cstdlib>
#include <string>

#include "absl/strings/match.h"
#include "common/eval/manifest.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const absl::string_view text(reinterpret_cast<const char*>(data), size);
  const auto entries = meshseek::ParseManifest(text, "data/fuzz.csv");
  if (!entries.ok()) {
    if (!absl::StartsWith(entries.status().message(), "data/fuzz.csv:")) std::abort();
    return 0;
  }
  // What the header documents: rows non-empty, at least one, each with a line.
  if (entries->empty()) std::abort();
  for (const meshseek::ManifestEntry& e : *entries) {
    if (e.id.empty() || e.label.empty() || e.path.empty() || e.line <= 0) std::abort();
  }
  return 0;
}
