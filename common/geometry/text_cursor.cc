#include "common/geometry/text_cursor.h"

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <string>
#include <system_error>
#include <type_traits>

#include "absl/strings/escaping.h"
#include "absl/strings/str_cat.h"

namespace meshseek::mesh_readers {

std::size_t TokenCursor::CountRest() {
  std::size_t count = 0;
  absl::string_view token;
  while (Next(&token)) ++count;
  return count;
}

template <typename T>
NumberParse TokenCursor::NextNumber(T* value, absl::string_view* token) {
  SkipSpace();
  if (p_ == end_) {
    *token = absl::string_view();
    return NumberParse::kMissing;
  }
  const char* begin = p_;
  const char* first = begin;
  if (*first == '+' && first + 1 != end_ && first[1] != '-') ++first;
  const std::from_chars_result parsed = std::from_chars(first, end_, *value);
  if (parsed.ec == std::errc() && (parsed.ptr == end_ || IsAsciiSpace(*parsed.ptr))) {
    p_ = parsed.ptr;
    *token = absl::string_view(begin, p_ - begin);
    if constexpr (std::is_floating_point_v<T>) {
      if (!std::isfinite(*value)) return NumberParse::kNonFinite;
    }
    return NumberParse::kOk;
  }
  while (p_ != end_ && !IsAsciiSpace(*p_)) ++p_;
  *token = absl::string_view(begin, p_ - begin);
  if (parsed.ec != std::errc::result_out_of_range || parsed.ptr != p_) {
    return NumberParse::kMalformed;
  }
  if constexpr (std::is_floating_point_v<T>) {
    // from_chars reports underflow ("1e-50") as out of range too, and leaves
    // the value unset; strto* gives the rounded tiny value (or 0), as the
    // stream-based readers did. Rare, so the copy does not matter.
    const std::string copy(first, p_);
    const T tiny = std::is_same_v<T, float> ? std::strtof(copy.c_str(), nullptr)
                                            : std::strtod(copy.c_str(), nullptr);
    if (std::isfinite(tiny) && std::abs(tiny) <= 1) {
      *value = tiny;
      return NumberParse::kOk;
    }
  }
  return NumberParse::kNonFinite;
}

NumberParse TokenCursor::NextFloat(float* value, absl::string_view* token) {
  return NextNumber(value, token);
}
NumberParse TokenCursor::NextDouble(double* value, absl::string_view* token) {
  return NextNumber(value, token);
}
NumberParse TokenCursor::NextInt64(int64_t* value, absl::string_view* token) {
  return NextNumber(value, token);
}

absl::Status LineError(std::size_t line_number, absl::string_view what) {
  return absl::InvalidArgumentError(absl::StrCat("line ", line_number, ": ", what));
}

std::string QuoteToken(absl::string_view token) {
  constexpr std::size_t kMaxShown = 40;
  const bool cut = token.size() > kMaxShown;
  return absl::StrCat("'", absl::CHexEscape(token.substr(0, kMaxShown)), cut ? "...'" : "'");
}

absl::Status CoordinateError(std::size_t line_number,
                             NumberParse result,
                             absl::string_view token,
                             absl::string_view expected) {
  switch (result) {
    case NumberParse::kNonFinite:
      return LineError(line_number, absl::StrCat("non-finite coordinate ", QuoteToken(token)));
    case NumberParse::kMissing:
      return LineError(line_number, absl::StrCat("expected ", expected, ", found the line's end"));
    default:
      return LineError(line_number,
                       absl::StrCat("expected ", expected, ", found ", QuoteToken(token)));
  }
}

}  // namespace meshseek::mesh_readers
