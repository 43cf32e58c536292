// Reading back the JSON reports meshseek writes (metrics.json), flattened to
// (path, value) pairs: `meshseek report` only needs to look values up and
// list them, so a tree type is not worth having. base/json.h stays
// write-only.
//
//   {"micro": {"NN": 93.3}, "parameters": {"method": "rld", "weights": [1, 2]}}
// flattens to
//   micro.NN = 93.3, parameters.method = rld, parameters.weights = [1, 2]
//
// Objects add ".key" to the path; an array of scalars is one value written
// "[a, b]"; an array holding objects or arrays adds "[i]" per element.
// Strings are unescaped (\uXXXX to UTF-8), numbers and literals kept as
// written, in document order.
#ifndef MESHSEEK_COMMON_EVAL_FLAT_JSON_H_
#define MESHSEEK_COMMON_EVAL_FLAT_JSON_H_

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"

namespace meshseek {

using FlatJson = std::vector<std::pair<std::string, std::string>>;

// Nesting deeper than this is refused rather than recursed into.
inline constexpr int kMaxFlatJsonDepth = 64;

// Flattens the JSON document `text`; `name` names it in errors.
// Errors: InvalidArgument "<name>: byte N: <what>" for malformed JSON, content
// after the document or nesting deeper than kMaxFlatJsonDepth.
absl::StatusOr<FlatJson> FlattenJson(absl::string_view text, absl::string_view name);

// The value at `path`, if present.
std::optional<std::string> FindFlatJson(const FlatJson& json, absl::string_view path);

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_EVAL_FLAT_JSON_H_
