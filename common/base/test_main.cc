// GoogleTest main shared by every meshseek test: seeds the global random
// generators before each test (COLMAP's convention) so a test never depends on
// what ran before it, quiets info logging, and gives the process a temporary
// folder of its own.
#include <gtest/gtest.h>
#include <stdlib.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <opencv2/core.hpp>
#include <string>

#include "common/base/logging.h"

namespace {

class SeedEveryTest : public ::testing::EmptyTestEventListener {
  void OnTestStart(const ::testing::TestInfo&) override {
    std::srand(0);
    cv::theRNG().state = 0x12345678;
  }
};

// CTest runs every case as its own process, several at once, and the cases of
// one suite write (and clear) the same names under ::testing::TempDir(). So
// each process gets a fresh folder under TEST_TMPDIR (or /tmp) as its
// TEST_TMPDIR, which servers it starts inherit. Returns the folder, or "" when
// none could be made (TempDir() then stays as it was).
std::string OwnTempDir() {
  const char* parent = std::getenv("TEST_TMPDIR");
  std::string pattern = (parent != nullptr && *parent != '\0') ? parent : "/tmp";
  pattern += "/meshseek-test-XXXXXX";
  if (mkdtemp(pattern.data()) == nullptr || setenv("TEST_TMPDIR", pattern.c_str(), 1) != 0) {
    return "";
  }
  return pattern;
}

}  // namespace

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  ::testing::UnitTest::GetInstance()->listeners().Append(new SeedEveryTest);
  meshseek::SetMinLogLevel(meshseek::LogLevel::kWarning);
  cv::setNumThreads(0);
  if (::testing::GTEST_FLAG(list_tests)) return RUN_ALL_TESTS();  // CTest's discovery
  const std::string temp = OwnTempDir();
  const int result = RUN_ALL_TESTS();
  // Kept when a case failed (to look at), or when MESHSEEK_KEEP_TEST_TMPDIR is
  // set: the sanitizer steps read the servers' logs there after the run.
  if (!temp.empty()) {
    if (result == 0 && std::getenv("MESHSEEK_KEEP_TEST_TMPDIR") == nullptr) {
      std::error_code ignored;
      std::filesystem::remove_all(temp, ignored);
    } else {
      std::printf("test files kept in %s\n", temp.c_str());
    }
  }
  return result;
}
