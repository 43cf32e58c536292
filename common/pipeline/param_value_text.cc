#include "common/pipeline/param_value_text.h"

#include <cstdio>
#include <cstdlib>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"

namespace meshseek {
namespace param_text {

std::string Format(int v) { return absl::StrCat(v); }
std::string Format(uint64_t v) { return absl::StrCat(v); }
std::string Format(bool v) { return v ? "true" : "false"; }
std::string Format(double v) {
  std::string text = absl::StrCat(v);
  if (std::strtod(text.c_str(), nullptr) == v) return text;
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.17g", v);
  return buffer;
}
std::string Format(const std::vector<double>& v) {
  std::string out;
  for (double x : v) absl::StrAppend(&out, out.empty() ? "" : ",", Format(x));
  return out;
}

void Parse(absl::string_view text, int* v) { (void)absl::SimpleAtoi(text, v); }
void Parse(absl::string_view text, uint64_t* v) { (void)absl::SimpleAtoi(text, v); }
void Parse(absl::string_view text, double* v) { (void)absl::SimpleAtod(text, v); }
void Parse(absl::string_view text, bool* v) { *v = text == "true"; }
void Parse(absl::string_view text, std::vector<double>* v) {
  v->clear();
  for (absl::string_view part : absl::StrSplit(text, ',', absl::SkipEmpty())) {
    double x = 0;
    (void)absl::SimpleAtod(part, &x);
    v->push_back(x);
  }
}

}  // namespace param_text
}  // namespace meshseek
