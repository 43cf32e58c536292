#include "common/base/base64.h"

#include <gtest/gtest.h>

#include <string>

namespace meshseek {
namespace {

// The test vectors of RFC 4648, section 10.
TEST(Base64Test, Rfc4648Vectors) {
  EXPECT_EQ(Base64Encode(""), "");
  EXPECT_EQ(Base64Encode("f"), "Zg==");
  EXPECT_EQ(Base64Encode("fo"), "Zm8=");
  EXPECT_EQ(Base64Encode("foo"), "Zm9v");
  EXPECT_EQ(Base64Encode("foob"), "Zm9vYg==");
  EXPECT_EQ(Base64Encode("fooba"), "Zm9vYmE=");
  EXPECT_EQ(Base64Encode("foobar"), "Zm9vYmFy");
}

TEST(Base64Test, HighBytesAndZerosUseTheWholeAlphabet) {
  EXPECT_EQ(Base64Encode(std::string("\xff\xff\xff", 3)), "////");
  EXPECT_EQ(Base64Encode(std::string("\xfb\xef\xbe", 3)), "++++");
  EXPECT_EQ(Base64Encode(std::string("\0\0\0\0", 4)), "AAAAAA==");
  // The 8-byte PNG signature, the start of every thumbnail's data: URI.
  EXPECT_EQ(Base64Encode("\x89PNG\r\n\x1a\n"), "iVBORw0KGgo=");
}

}  // namespace
}  // namespace meshseek
