// GoogleTest main shared by every meshseek test: seeds the global random
// generators before each test (COLMAP's convention) so a test never depends on
// what ran before it, and quiets info logging.
#include <gtest/gtest.h>

#include <cstdlib>
#include <opencv2/core.hpp>

#include "common/base/logging.h"

namespace {

class SeedEveryTest : public ::testing::EmptyTestEventListener {
  void OnTestStart(const ::testing::TestInfo&) override {
    std::srand(0);
    cv::theRNG().state = 0x12345678;
  }
};

}  // namespace

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  ::testing::UnitTest::GetInstance()->listeners().Append(new SeedEveryTest);
  meshseek::SetMinLogLevel(meshseek::LogLevel::kWarning);
  cv::setNumThreads(0);
  return RUN_ALL_TESTS();
}
