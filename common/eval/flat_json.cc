#include "common/eval/flat_json.h"

#include <cctype>
#include <cstdlib>

#include "absl/strings/str_cat.h"

namespace meshseek {
namespace {

class Flattener {
 public:
  Flattener(absl::string_view text, absl::string_view name) : text_(text), name_(name) {}

  absl::StatusOr<FlatJson> Run() {
    SkipSpace();
    if (!Value("", 0)) return error_;
    SkipSpace();
    if (pos_ != text_.size()) {
      Fail("content after the document");
      return error_;
    }
    return std::move(out_);
  }

 private:
  bool Fail(absl::string_view what) {
    error_ = absl::InvalidArgumentError(absl::StrCat(name_, ": byte ", pos_, ": ", what));
    return false;
  }
  void SkipSpace() {
    while (pos_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[pos_]))) ++pos_;
  }
  bool Peek(char c) {
    SkipSpace();
    return pos_ < text_.size() && text_[pos_] == c;
  }

  // A string at pos_ (which is '"'), unescaped into *out.
  bool String(std::string* out) {
    ++pos_;
    while (pos_ < text_.size()) {
      const char c = text_[pos_++];
      if (c == '"') return true;
      if (c != '\\') {
        out->push_back(c);
        continue;
      }
      if (pos_ >= text_.size()) break;
      const char e = text_[pos_++];
      switch (e) {
        case 'n':
          out->push_back('\n');
          break;
        case 't':
          out->push_back('\t');
          break;
        case 'r':
          out->push_back('\r');
          break;
        case 'b':
          out->push_back('\b');
          break;
        case 'f':
          out->push_back('\f');
          break;
        case '"':
        case '\\':
        case '/':
          out->push_back(e);
          break;
        case 'u': {
          if (pos_ + 4 > text_.size()) return Fail("truncated \\u escape");
          const std::string hex(text_.substr(pos_, 4));
          char* end = nullptr;
          const unsigned long cp = std::strtoul(hex.c_str(), &end, 16);
          if (end != hex.c_str() + 4) return Fail("bad \\u escape");
          pos_ += 4;
          // UTF-8 of the code point; surrogate halves (never written by
          // meshseek) become '?'.
          if (cp < 0x80) {
            out->push_back(static_cast<char>(cp));
          } else if (cp < 0x800) {
            out->push_back(static_cast<char>(0xc0 | (cp >> 6)));
            out->push_back(static_cast<char>(0x80 | (cp & 0x3f)));
          } else if (cp >= 0xd800 && cp < 0xe000) {
            out->push_back('?');
          } else {
            out->push_back(static_cast<char>(0xe0 | (cp >> 12)));
            out->push_back(static_cast<char>(0x80 | ((cp >> 6) & 0x3f)));
            out->push_back(static_cast<char>(0x80 | (cp & 0x3f)));
          }
          break;
        }
        default:
          return Fail(absl::StrCat("bad escape '\\", std::string(1, e), "'"));
      }
    }
    return Fail("unterminated string");
  }

  // A number or literal, as written.
  bool Scalar(std::string* out) {
    const std::size_t start = pos_;
    while (pos_ < text_.size() &&
           (std::isalnum(static_cast<unsigned char>(text_[pos_])) || text_[pos_] == '-' ||
            text_[pos_] == '+' || text_[pos_] == '.')) {
      ++pos_;
    }
    *out = std::string(text_.substr(start, pos_ - start));
    if (out->empty()) return Fail("expected a value");
    if (*out == "true" || *out == "false" || *out == "null") return true;
    char* end = nullptr;
    std::strtod(out->c_str(), &end);
    if (end != out->c_str() + out->size()) return Fail(absl::StrCat("bad value '", *out, "'"));
    return true;
  }

  // The value at pos_, added to out_ under `path`; *scalar (optional) says
  // whether it was a string, number or literal.
  bool Value(const std::string& path, int depth, bool* scalar = nullptr) {
    if (scalar != nullptr) *scalar = false;
    if (depth > kMaxFlatJsonDepth) return Fail("nested too deeply");
    SkipSpace();
    if (pos_ >= text_.size()) return Fail("unexpected end");
    const char c = text_[pos_];
    if (c == '{') {
      ++pos_;
      if (Peek('}')) return ++pos_, true;
      while (true) {
        if (!Peek('"')) return Fail("expected a key");
        std::string key;
        if (!String(&key)) return false;
        if (!Peek(':')) return Fail("expected ':'");
        ++pos_;
        if (!Value(path.empty() ? key : absl::StrCat(path, ".", key), depth + 1)) return false;
        if (Peek(',')) {
          ++pos_;
        } else if (Peek('}')) {
          return ++pos_, true;
        } else {
          return Fail("expected ',' or '}'");
        }
      }
    }
    if (c == '[') return Array(path, depth);
    std::string value;
    if (c == '"' ? !String(&value) : !Scalar(&value)) return false;
    out_.emplace_back(path, std::move(value));
    if (scalar != nullptr) *scalar = true;
    return true;
  }

  // An array: scalars joined into one value, anything else element by element.
  bool Array(const std::string& path, int depth) {
    const std::size_t first = out_.size();
    ++pos_;
    std::string joined = "[";
    bool scalars = true;
    int index = 0;
    if (Peek(']')) {
      ++pos_;
      out_.emplace_back(path, "[]");
      return true;
    }
    while (true) {
      bool scalar = false;
      if (!Value(absl::StrCat(path, "[", index, "]"), depth + 1, &scalar)) return false;
      if (scalar) {
        absl::StrAppend(&joined, index > 0 ? ", " : "", out_.back().second);
      } else {
        scalars = false;
      }
      ++index;
      if (Peek(',')) {
        ++pos_;
      } else if (Peek(']')) {
        ++pos_;
        break;
      } else {
        return Fail("expected ',' or ']'");
      }
    }
    if (scalars) {
      out_.resize(first);
      out_.emplace_back(path, joined + "]");
    }
    return true;
  }

  absl::string_view text_;
  absl::string_view name_;
  std::size_t pos_ = 0;
  FlatJson out_;
  absl::Status error_;
};

}  // namespace

absl::StatusOr<FlatJson> FlattenJson(absl::string_view text, absl::string_view name) {
  return Flattener(text, name).Run();
}

std::optional<std::string> FindFlatJson(const FlatJson& json, absl::string_view path) {
  for (const auto& [key, value] : json) {
    if (key == path) return value;
  }
  return std::nullopt;
}

}  // namespace meshseek
