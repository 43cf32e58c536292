// A small JSON value for writing reports (metrics.json and friends).
//
// Objects keep insertion order so that files diff cleanly. Only writing is
// supported here; the evaluation report reads back the metrics.json that eval
// wrote with common/eval/flat_json.h. Non-finite numbers are written as null,
// since JSON has no NaN.
#ifndef MESHSEEK_COMMON_BASE_JSON_H_
#define MESHSEEK_COMMON_BASE_JSON_H_

#include <cstdint>
#include <string>
#include <utility>
#include <variant>
#include <vector>

namespace meshseek {

class Json {
 public:
  using Object = std::vector<std::pair<std::string, Json>>;
  using Array = std::vector<Json>;

  Json() : value_(nullptr) {}
  Json(std::nullptr_t) : value_(nullptr) {}
  Json(bool b) : value_(b) {}
  Json(int v) : value_(static_cast<int64_t>(v)) {}
  Json(int64_t v) : value_(v) {}
  Json(uint64_t v) : value_(static_cast<int64_t>(v)) {}
  Json(double v) : value_(v) {}
  Json(const char* s) : value_(std::string(s)) {}
  Json(std::string s) : value_(std::move(s)) {}

  static Json MakeObject() {
    Json j;
    j.value_ = Object{};
    return j;
  }
  static Json MakeArray() {
    Json j;
    j.value_ = Array{};
    return j;
  }

  // Object member (replaces an existing key). The value must be an object.
  Json& Set(const std::string& key, Json value);
  // Array element. The value must be an array.
  Json& Push(Json value);

  // Pretty-printed with `indent` spaces per level (0: one line).
  std::string Dump(int indent = 2) const;

 private:
  void DumpTo(std::string* out, int indent, int depth) const;

  std::variant<std::nullptr_t, bool, int64_t, double, std::string, Object, Array> value_;
};

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_BASE_JSON_H_
