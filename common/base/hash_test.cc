#include "common/base/hash.h"

#include <gtest/gtest.h>

namespace meshseek {
namespace {

// Test vectors of the FNV reference (Landon Curt Noll's test suite).
TEST(Fnv1a64Test, ReferenceVectors) {
  EXPECT_EQ(Fnv1a64(""), 0xcbf29ce484222325ull);
  EXPECT_EQ(Fnv1a64("a"), 0xaf63dc4c8601ec8cull);
  EXPECT_EQ(Fnv1a64("foobar"), 0x85944171f73967e8ull);
  EXPECT_EQ(Fnv1a64("chongo was here!\n"), 0x46810940eff5f915ull);
}

TEST(Fnv1a64Test, LegacyBasisOnlyWhenAsked) {
  EXPECT_EQ(Fnv1a64("", kLegacyFnv1a64OffsetBasis), kLegacyFnv1a64OffsetBasis);
  EXPECT_NE(Fnv1a64("a", kLegacyFnv1a64OffsetBasis), Fnv1a64("a"));
}

}  // namespace
}  // namespace meshseek
