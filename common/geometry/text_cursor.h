// Line-oriented scanning of ASCII mesh files (OFF, OBJ, PLY bodies, STL): lines
// with their numbers, whitespace-separated tokens, and numbers parsed with
// std::from_chars (locale-free, correctly rounded, no allocation).
//
// Internal to common/geometry (the format readers); not part of the public API.
// Speed matters here: a 200 MB OBJ file is ten million lines, so lines are found
// with memchr, numbers are parsed in place (no token copies), and errors are
// only formatted on the failure path.
#ifndef MESHSEEK_COMMON_GEOMETRY_TEXT_CURSOR_H_
#define MESHSEEK_COMMON_GEOMETRY_TEXT_CURSOR_H_

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>

#include "absl/status/status.h"
#include "absl/strings/string_view.h"

namespace meshseek::mesh_readers {

// Splits text into lines. A line excludes its '\n' and a '\r' just before it
// (CRLF files); the last line need not end with '\n'.
class LineCursor {
 public:
  // `first_line_number` is the number the first line of `text` gets (a PLY
  // body starts after its header lines).
  explicit LineCursor(absl::string_view text, std::size_t first_line_number = 1)
      : text_(text), next_line_number_(first_line_number) {}

  // The next line, or false at the end of the text.
  bool Next(absl::string_view* line) {
    if (pos_ >= text_.size()) return false;
    const char* begin = text_.data() + pos_;
    const std::size_t left = text_.size() - pos_;
    const void* newline = std::memchr(begin, '\n', left);
    std::size_t length = newline ? static_cast<const char*>(newline) - begin : left;
    pos_ += newline ? length + 1 : length;
    if (length > 0 && begin[length - 1] == '\r') --length;
    *line = absl::string_view(begin, length);
    line_number_ = next_line_number_++;
    return true;
  }

  // Number of the line last returned by Next (0 before the first).
  std::size_t line_number() const { return line_number_; }
  // Byte offset, in `text`, just past the line last returned (and its '\n').
  std::size_t offset() const { return pos_; }
  // Bytes not yet returned.
  std::size_t remaining() const { return text_.size() - pos_; }

 private:
  absl::string_view text_;
  std::size_t pos_ = 0;
  std::size_t line_number_ = 0;
  std::size_t next_line_number_;
};

// What parsing one number token found.
enum class NumberParse {
  kOk,
  kMissing,    // the line has no more tokens
  kMalformed,  // the token is not a number of the requested kind
  kNonFinite,  // "nan", "inf", or a value beyond the type's range ("1e999")
};

inline bool IsAsciiSpace(char c) {
  return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
}

// The line up to the first `comment` character ('#' in OFF and OBJ).
inline absl::string_view StripComment(absl::string_view line, char comment) {
  const void* hit = std::memchr(line.data(), comment, line.size());
  return hit ? line.substr(0, static_cast<const char*>(hit) - line.data()) : line;
}

// Whitespace-separated tokens of one line, and numbers read from them. A
// number must be the whole token: "1.5abc" and "1,5" are malformed. A leading
// '+' is accepted (std::from_chars does not accept one).
class TokenCursor {
 public:
  explicit TokenCursor(absl::string_view line) : p_(line.data()), end_(line.data() + line.size()) {}

  bool Next(absl::string_view* token) {
    SkipSpace();
    if (p_ == end_) return false;
    const char* begin = p_;
    while (p_ != end_ && !IsAsciiSpace(*p_)) ++p_;
    *token = absl::string_view(begin, p_ - begin);
    return true;
  }
  // True when only whitespace is left.
  bool Done() {
    SkipSpace();
    return p_ == end_;
  }
  // What is left of the line, from the next token on.
  absl::string_view Rest() {
    SkipSpace();
    return absl::string_view(p_, end_ - p_);
  }
  // Counts the tokens left, consuming them.
  std::size_t CountRest();

  // The next token as a number; `*token` is that token (empty for kMissing),
  // and the cursor has moved past it.
  NumberParse NextFloat(float* value, absl::string_view* token);
  NumberParse NextDouble(double* value, absl::string_view* token);
  NumberParse NextInt64(int64_t* value, absl::string_view* token);

 private:
  void SkipSpace() {
    while (p_ != end_ && IsAsciiSpace(*p_)) ++p_;
  }
  template <typename T>
  NumberParse NextNumber(T* value, absl::string_view* token);

  const char* p_;
  const char* end_;
};

// `token` quoted for an error message: at most 40 characters, non-printable
// bytes escaped (a binary file read as text must not garble the message).
std::string QuoteToken(absl::string_view token);

// InvalidArgument "line N: <what>".
absl::Status LineError(std::size_t line_number, absl::string_view what);

// The error for a token NextFloat/NextDouble refused, e.g. "line 4: non-finite
// coordinate 'nan'", "line 4: expected x y z, got 'abc'" or, for kMissing,
// "line 4: expected x y z".
absl::Status CoordinateError(std::size_t line_number,
                             NumberParse result,
                             absl::string_view token,
                             absl::string_view expected = "x y z");

}  // namespace meshseek::mesh_readers

#endif  // MESHSEEK_COMMON_GEOMETRY_TEXT_CURSOR_H_
