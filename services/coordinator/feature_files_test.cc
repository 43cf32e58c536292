#include "services/coordinator/feature_files.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "common/base/file_io.h"

namespace meshseek {
namespace {

class FeatureFilesTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::path(::testing::TempDir()) /
           ::testing::UnitTest::GetInstance()->current_test_info()->name();
    std::filesystem::remove_all(dir_);
    auto files = FeatureFiles::Open((dir_ / "features").string());
    ASSERT_TRUE(files.ok()) << files.status();
    files_.emplace(*std::move(files));
  }
  std::filesystem::path dir_;
  std::optional<FeatureFiles> files_;
};

TEST_F(FeatureFilesTest, KeepsEachModelsPayloadApart) {
  const std::string payload(100000, '\x7f');
  ASSERT_TRUE(files_->Put("c~dld", "m1", payload).ok());
  ASSERT_TRUE(files_->Put("c~lsf", "m1", "other").ok());
  ASSERT_TRUE(files_->Put("c~dld", "m2", "").ok());
  EXPECT_EQ(files_->Get("c~dld", "m1"), payload);
  EXPECT_EQ(files_->Get("c~lsf", "m1"), "other");
  EXPECT_EQ(files_->Get("c~dld", "m2"), "");  // stored and empty is not absent
  EXPECT_EQ(files_->Get("c~dld", "m3"), std::nullopt);
  // Replacing leaves no temporary behind.
  ASSERT_TRUE(files_->Put("c~dld", "m1", "again").ok());
  EXPECT_EQ(files_->Get("c~dld", "m1"), "again");
  std::size_t files = 0;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(files_->dir())) {
    files += entry.is_regular_file();
  }
  EXPECT_EQ(files, 3u);
  files_->Remove("c~dld", "m1");
  files_->Remove("c~dld", "m1");  // twice: nothing to remove is fine
  EXPECT_EQ(files_->Get("c~dld", "m1"), std::nullopt);
  EXPECT_EQ(files_->Get("c~lsf", "m1"), "other");
}

// Whatever damage a file has, it reads as absent (the build extracts that
// model again), never as other features.
TEST_F(FeatureFilesTest, ADamagedFileReadsAsAbsent) {
  const std::string payload = "0123456789abcdef0123456789abcdef";
  const std::string path = files_->PathOf("c", "m");
  const auto put = [&] { ASSERT_TRUE(files_->Put("c", "m", payload).ok()); };
  const auto rewrite = [&](const std::function<void(std::string*)>& damage) {
    put();
    std::string bytes = *ReadFileToString(path);
    damage(&bytes);
    ASSERT_TRUE(WriteStringToFile(path, bytes).ok());
  };
  put();
  ASSERT_EQ(files_->Get("c", "m"), payload);
  rewrite([](std::string* b) { b->resize(b->size() - 1); });  // cut short
  EXPECT_EQ(files_->Get("c", "m"), std::nullopt);
  rewrite([](std::string* b) { b->back() ^= 1; });  // one bit of the payload
  EXPECT_EQ(files_->Get("c", "m"), std::nullopt);
  rewrite([](std::string* b) { b->push_back('x'); });  // longer
  EXPECT_EQ(files_->Get("c", "m"), std::nullopt);
  rewrite([](std::string* b) { (*b)[0] = 'X'; });  // not ours
  EXPECT_EQ(files_->Get("c", "m"), std::nullopt);
  rewrite([](std::string* b) { b->resize(10); });  // within the header
  EXPECT_EQ(files_->Get("c", "m"), std::nullopt);
  rewrite([](std::string* b) { b->clear(); });
  EXPECT_EQ(files_->Get("c", "m"), std::nullopt);
  // Another model's file under this model's name (as a hash collision
  // would leave it): its key does not match.
  ASSERT_TRUE(files_->Put("c", "other", payload).ok());
  std::filesystem::copy_file(files_->PathOf("c", "other"), path,
                             std::filesystem::copy_options::overwrite_existing);
  EXPECT_EQ(files_->Get("c", "m"), std::nullopt);
}

TEST_F(FeatureFilesTest, RefusesAFolderItCannotCreate) {
  ASSERT_TRUE(WriteStringToFile((dir_ / "plain").string(), "a file").ok());
  auto files = FeatureFiles::Open((dir_ / "plain" / "features").string());
  EXPECT_EQ(files.status().code(), absl::StatusCode::kPermissionDenied);
  EXPECT_NE(files.status().message().find("plain"), std::string::npos);
}

}  // namespace
}  // namespace meshseek
