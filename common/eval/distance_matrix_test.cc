#include "common/eval/distance_matrix.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>

namespace meshseek {
namespace {

using ::testing::HasSubstr;

// A fresh folder under the test temp dir, one per test.
std::string TestDir() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const std::string dir = ::testing::TempDir() + "/distance_matrix_test_" + info->name();
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

std::string ReadBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

TEST(DistanceMatrixTest, RoundTripsEveryBitIncludingInfinityAndNegativeZero) {
  const float inf = std::numeric_limits<float>::infinity();
  const std::vector<float> matrix = {0.0f,
                                     1.5f,
                                     -0.0f,
                                     inf,
                                     std::numeric_limits<float>::denorm_min(),
                                     3.4e38f,
                                     -2.25f,
                                     1e-7f,
                                     0.1f};
  const std::string path = TestDir() + "/d.bin";
  ASSERT_TRUE(WriteDistanceMatrix(path, matrix, 3).ok());
  const auto read = ReadDistanceMatrix(path, 3);
  ASSERT_TRUE(read.ok()) << read.status();
  ASSERT_EQ(read->size(), matrix.size());
  for (std::size_t i = 0; i < matrix.size(); ++i) {
    EXPECT_EQ(std::memcmp(&(*read)[i], &matrix[i], sizeof(float)), 0) << "entry " << i;
  }
}

TEST(DistanceMatrixTest, WritesLittleEndianRowMajorWithoutHeader) {
  const std::string path = TestDir() + "/d.bin";
  // 1.0f = 0x3F800000, 2.0f = 0x40000000.
  ASSERT_TRUE(WriteDistanceMatrix(path, {0.0f, 1.0f, 2.0f, 0.0f}, 2).ok());
  EXPECT_EQ(ReadBytes(path),
            std::string("\x00\x00\x00\x00"
                        "\x00\x00\x80\x3F"
                        "\x00\x00\x00\x40"
                        "\x00\x00\x00\x00",
                        16));
}

TEST(DistanceMatrixTest, ReadRejectsAFileOfTheWrongSize) {
  const std::string path = TestDir() + "/d.bin";
  ASSERT_TRUE(WriteDistanceMatrix(path, std::vector<float>(9, 1.0f), 3).ok());
  const auto read = ReadDistanceMatrix(path, 2);
  ASSERT_FALSE(read.ok());
  EXPECT_EQ(read.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(read.status().message(),
              HasSubstr(path + ": expected 2 x 2 float32 = 16 bytes, file has 36 bytes"));
  EXPECT_THAT(ReadDistanceMatrix(path, 4).status().message(),
              HasSubstr("expected 4 x 4 float32 = 64 bytes, file has 36 bytes"));
}

TEST(DistanceMatrixTest, ReadRejectsNanNamingRowAndColumn) {
  const std::string path = TestDir() + "/d.bin";
  // Written by hand, since WriteDistanceMatrix refuses NaN: row 1, column 0 of 2 x 2.
  const float values[4] = {0.0f, 1.0f, std::numeric_limits<float>::quiet_NaN(), 0.0f};
  std::ofstream(path, std::ios::binary)
      .write(reinterpret_cast<const char*>(values), sizeof(values));
  const auto read = ReadDistanceMatrix(path, 2);
  ASSERT_FALSE(read.ok());
  EXPECT_THAT(read.status().message(), HasSubstr(path + ": NaN at row 1, column 0"));
}

TEST(DistanceMatrixTest, ReadOfAMissingFileOrAFolderFails) {
  const std::string dir = TestDir();
  EXPECT_EQ(ReadDistanceMatrix(dir + "/absent.bin", 2).status().code(),
            absl::StatusCode::kNotFound);
  EXPECT_FALSE(ReadDistanceMatrix(dir, 2).ok());
}

TEST(DistanceMatrixTest, WriteRejectsWrongSizeAndNan) {
  const std::string path = TestDir() + "/d.bin";
  EXPECT_THAT(WriteDistanceMatrix(path, std::vector<float>(5), 2).message(),
              HasSubstr("got 5 distances for a 2 x 2 matrix (expected 4)"));
  std::vector<float> matrix(9, 0.0f);
  matrix[2 * 3 + 1] = std::nanf("");
  EXPECT_THAT(WriteDistanceMatrix(path, matrix, 3).message(), HasSubstr("NaN at row 2, column 1"));
  EXPECT_FALSE(std::filesystem::exists(path));
}

TEST(DistanceMatrixTest, RejectsSizesThatOverflow) {
  const std::size_t huge = std::size_t{1} << 40;
  EXPECT_THAT(ReadDistanceMatrix("unused.bin", huge).status().message(), HasSubstr("is too large"));
  EXPECT_THAT(WriteDistanceMatrix("unused.bin", {}, huge).message(), HasSubstr("is too large"));
}

}  // namespace
}  // namespace meshseek
