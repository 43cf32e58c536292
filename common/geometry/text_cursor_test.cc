#include "common/geometry/text_cursor.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

namespace meshseek::mesh_readers {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;

TEST(LineCursorTest, SplitsLinesStripsCrAndNumbersThem) {
  LineCursor lines("a b\r\n\nlast", 7);
  std::vector<std::string> seen;
  std::vector<std::size_t> numbers;
  absl::string_view line;
  while (lines.Next(&line)) {
    seen.emplace_back(line);
    numbers.push_back(lines.line_number());
  }
  EXPECT_THAT(seen, ElementsAre("a b", "", "last"));
  EXPECT_THAT(numbers, ElementsAre(7, 8, 9));
  EXPECT_EQ(lines.remaining(), 0u);
}

TEST(LineCursorTest, OffsetPointsPastTheNewline) {
  LineCursor lines("OFF BINARY\n\x01\x02");
  absl::string_view line;
  ASSERT_TRUE(lines.Next(&line));
  EXPECT_EQ(line, "OFF BINARY");
  EXPECT_EQ(lines.offset(), 11u);
}

TEST(TokenCursorTest, TokensAndComments) {
  TokenCursor tokens(StripComment("  v\t1 2  # a comment", '#'));
  absl::string_view token;
  ASSERT_TRUE(tokens.Next(&token));
  EXPECT_EQ(token, "v");
  EXPECT_EQ(tokens.CountRest(), 2u);
  EXPECT_TRUE(tokens.Done());
}

float ParseFloatOrDie(absl::string_view text, NumberParse expected = NumberParse::kOk) {
  TokenCursor tokens(text);
  float value = -1;
  absl::string_view token;
  EXPECT_EQ(tokens.NextFloat(&value, &token), expected) << text;
  return value;
}

TEST(TokenCursorTest, FloatsAreCorrectlyRoundedAndWhole) {
  EXPECT_EQ(ParseFloatOrDie("0.1"), 0.1f);
  EXPECT_EQ(ParseFloatOrDie("+2.5"), 2.5f);  // from_chars alone refuses '+'
  EXPECT_EQ(ParseFloatOrDie("-.5e-3"), -0.0005f);
  EXPECT_EQ(ParseFloatOrDie("44.399700"), 44.3997f);
  EXPECT_EQ(ParseFloatOrDie("1e-50"), 0.0f);  // underflow rounds to zero, as strtof does
  EXPECT_GT(ParseFloatOrDie("1e-40"), 0.0f);  // a denormal
  ParseFloatOrDie("1,5", NumberParse::kMalformed);
  ParseFloatOrDie("1.5abc", NumberParse::kMalformed);
  ParseFloatOrDie("+-1", NumberParse::kMalformed);
  ParseFloatOrDie("+", NumberParse::kMalformed);
  ParseFloatOrDie("0x10", NumberParse::kMalformed);
  ParseFloatOrDie("", NumberParse::kMissing);
  for (const char* bad : {"nan", "-inf", "infinity", "1e39", "1e999", "-1e999"}) {
    ParseFloatOrDie(bad, NumberParse::kNonFinite);
  }
}

TEST(TokenCursorTest, DoublesAndIntegers) {
  TokenCursor tokens("1e300 -7 +12 3.0 99999999999999999999");
  double d = 0;
  int64_t i = 0;
  absl::string_view token;
  EXPECT_EQ(tokens.NextDouble(&d, &token), NumberParse::kOk);
  EXPECT_EQ(d, 1e300);
  EXPECT_EQ(tokens.NextInt64(&i, &token), NumberParse::kOk);
  EXPECT_EQ(i, -7);
  EXPECT_EQ(tokens.NextInt64(&i, &token), NumberParse::kOk);
  EXPECT_EQ(i, 12);
  EXPECT_EQ(tokens.NextInt64(&i, &token), NumberParse::kMalformed);
  EXPECT_EQ(token, "3.0");
  EXPECT_EQ(tokens.NextInt64(&i, &token), NumberParse::kNonFinite);  // out of range
  EXPECT_EQ(tokens.NextInt64(&i, &token), NumberParse::kMissing);
}

TEST(TokenCursorTest, ErrorsNameTheLineAndQuoteTheToken) {
  EXPECT_THAT(std::string(CoordinateError(4, NumberParse::kNonFinite, "nan").message()),
              HasSubstr("line 4: non-finite coordinate 'nan'"));
  const std::string binary = QuoteToken(std::string("a\0b", 3));
  EXPECT_THAT(binary, HasSubstr("\\x00"));
  EXPECT_EQ(binary.find('\0'), std::string::npos);
  EXPECT_EQ(QuoteToken(std::string(100, 'x')).size(), 40u + 5u);
}

}  // namespace
}  // namespace meshseek::mesh_readers
