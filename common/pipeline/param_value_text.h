// Parameter values as text, the form they travel in (flags, PipelineParams.values,
// a collection's stored parameters): canonical formatting, so that one value
// always reads the same, and parsing of text already checked by
// CheckParamValue (pipeline_params.cc). Internal to common/pipeline.
#ifndef MESHSEEK_COMMON_PIPELINE_PARAM_VALUE_TEXT_H_
#define MESHSEEK_COMMON_PIPELINE_PARAM_VALUE_TEXT_H_

#include <cstdint>
#include <string>
#include <vector>

#include "absl/strings/string_view.h"

namespace meshseek {
namespace param_text {

/// Integers in full, booleans "true"/"false", doubles with six significant
/// digits when they read back to the same double (every default) and all
/// seventeen otherwise, lists comma-separated.
std::string Format(int v);
std::string Format(uint64_t v);
std::string Format(bool v);
std::string Format(double v);
std::string Format(const std::vector<double>& v);

/// Text already checked against the type: no error path.
void Parse(absl::string_view text, int* v);
void Parse(absl::string_view text, uint64_t* v);
void Parse(absl::string_view text, double* v);
void Parse(absl::string_view text, bool* v);
void Parse(absl::string_view text, std::vector<double>* v);

}  // namespace param_text
}  // namespace meshseek

#endif  // MESHSEEK_COMMON_PIPELINE_PARAM_VALUE_TEXT_H_
