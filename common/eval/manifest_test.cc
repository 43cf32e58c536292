#include "common/eval/manifest.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <climits>
#include <filesystem>
#include <fstream>
#include <string>

namespace meshseek {
namespace {

using ::testing::HasSubstr;

// A fresh folder under the test temp dir, one per test.
std::string TestDir() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const std::string dir = ::testing::TempDir() + "/manifest_test_" + info->name();
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

std::string WriteFile(const std::string& dir, const std::string& name, const std::string& text) {
  const std::string path = dir + "/" + name;
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

// The error message ReadManifest gives for `text`, or "OK".
std::string ReadError(const std::string& text) {
  const std::string path = WriteFile(TestDir(), "m.csv", text);
  const auto entries = ReadManifest(path);
  return entries.ok() ? "OK" : std::string(entries.status().message());
}

TEST(ManifestTest, ReadsRowsInOrderAndResolvesPathsAgainstTheManifestFolder) {
  const std::string dir = TestDir();
  const std::string path = WriteFile(dir,
                                     "manifest.csv",
                                     "id,class,path\n"
                                     "m2,chair,models/m2.off\n"
                                     "m1,-1,/abs/m1.obj\n"
                                     "m0,chair,../up/m0.ply\n");
  const auto entries = ReadManifest(path);
  ASSERT_TRUE(entries.ok()) << entries.status();
  ASSERT_EQ(entries->size(), 3u);
  EXPECT_EQ((*entries)[0].id, "m2");
  EXPECT_EQ((*entries)[0].label, "chair");
  EXPECT_EQ((*entries)[0].path, dir + "/models/m2.off");
  EXPECT_EQ((*entries)[0].line, 2);
  EXPECT_EQ((*entries)[1].id, "m1");
  EXPECT_EQ((*entries)[1].label, "-1");
  EXPECT_EQ((*entries)[1].path, "/abs/m1.obj");
  EXPECT_EQ((*entries)[1].line, 3);
  EXPECT_EQ((*entries)[2].path, dir + "/../up/m0.ply");
  EXPECT_EQ((*entries)[2].line, 4);
}

TEST(ManifestTest, PathOfAManifestInTheWorkingDirectoryStaysRelative) {
  const std::string dir = TestDir();
  WriteFile(dir, "manifest.csv", "id,class,path\na,c,models/a.off\n");
  char old_cwd[PATH_MAX];
  ASSERT_NE(getcwd(old_cwd, sizeof(old_cwd)), nullptr);
  ASSERT_EQ(chdir(dir.c_str()), 0);
  const auto entries = ReadManifest("manifest.csv");
  ASSERT_EQ(chdir(old_cwd), 0);
  ASSERT_TRUE(entries.ok()) << entries.status();
  EXPECT_EQ((*entries)[0].path, "models/a.off");
}

TEST(ManifestTest, ToleratesColumnOrderExtraColumnsQuotesCrlfBomAndBlankLines) {
  const std::string dir = TestDir();
  const std::string path = WriteFile(dir,
                                     "m.csv",
                                     "\xEF\xBB\xBFpath, note ,Class,ID\r\n"
                                     "\r\n"
                                     "\"x,y.off\",\"say \"\"hi\"\"\", cup ,  \"a b\" \r\n"
                                     "   \n"
                                     "/z.off,,\"-1\",b\r\n");
  const auto entries = ReadManifest(path);
  ASSERT_TRUE(entries.ok()) << entries.status();
  ASSERT_EQ(entries->size(), 2u);
  EXPECT_EQ((*entries)[0].id, "a b");
  EXPECT_EQ((*entries)[0].label, "cup");
  EXPECT_EQ((*entries)[0].path, dir + "/x,y.off");
  EXPECT_EQ((*entries)[0].line, 3);
  EXPECT_EQ((*entries)[1].id, "b");
  EXPECT_EQ((*entries)[1].label, "-1");
  EXPECT_EQ((*entries)[1].path, "/z.off");
  EXPECT_EQ((*entries)[1].line, 5);
}

TEST(ManifestTest, MissingFileIsNotFoundAndNamesThePath) {
  const std::string path = TestDir() + "/absent.csv";
  const auto entries = ReadManifest(path);
  ASSERT_FALSE(entries.ok());
  EXPECT_EQ(entries.status().code(), absl::StatusCode::kNotFound);
  EXPECT_THAT(entries.status().message(), HasSubstr(path));
}

TEST(ManifestTest, FolderIsRejected) {
  const std::string dir = TestDir();
  EXPECT_THAT(ReadManifest(dir).status().message(), HasSubstr(dir + ": is a folder"));
}

TEST(ManifestTest, AFileLargerThanTheLimitIsRefusedBeforeItIsRead) {
  // A sparse file: its size is what counts, nothing of it needs to exist.
  const std::string path = TestDir() + "/huge.csv";
  std::ofstream(path) << "id,class,path\n";
  std::filesystem::resize_file(path, kMaxManifestBytes + 1);
  const auto entries = ReadManifest(path);
  EXPECT_EQ(entries.status().code(), absl::StatusCode::kResourceExhausted);
  EXPECT_THAT(entries.status().message(), HasSubstr(path + ": 268435457 bytes, more than the limit"));
}

TEST(ManifestTest, ParseFromMemoryEqualsReadingTheFile) {
  const std::string text = "id,class,path\nm1,a,x.off\nm2,b,/abs/y.off\n";
  const std::string path = WriteFile(TestDir(), "m.csv", text);
  const auto read = ReadManifest(path);
  const auto parsed = ParseManifest(text, path);
  ASSERT_TRUE(read.ok() && parsed.ok()) << read.status() << parsed.status();
  ASSERT_EQ(read->size(), parsed->size());
  for (std::size_t i = 0; i < read->size(); ++i) {
    EXPECT_EQ((*read)[i].path, (*parsed)[i].path);
    EXPECT_EQ((*read)[i].line, (*parsed)[i].line);
  }
  EXPECT_THAT(ParseManifest("id,class,path\nm1,,x\n", "in/memory.csv").status().message(),
              HasSubstr("in/memory.csv:2: empty class for id 'm1'"));
}

TEST(ManifestTest, ErrorsNameFileLineAndValue) {
  EXPECT_THAT(ReadError(""), HasSubstr("m.csv:1: no header"));
  EXPECT_THAT(ReadError("\n\n"), HasSubstr("m.csv:1: no header"));
  EXPECT_THAT(ReadError("id,class\na,b\n"),
              HasSubstr("m.csv:1: header 'id,class' must name the columns id, class and path"));
  EXPECT_THAT(ReadError("\nid,label,path\n"), HasSubstr("m.csv:2: header 'id,label,path'"));
  EXPECT_THAT(ReadError("id,class,path,Id\n"), HasSubstr("m.csv:1: column 'id' appears twice"));
  EXPECT_THAT(ReadError("id,class,path\n"), HasSubstr("m.csv:1: header but no models"));
  EXPECT_THAT(ReadError("id,class,path\na,c,p\n\nb,c\n"),
              HasSubstr("m.csv:4: expected 3 fields as in the header, got 2 in 'b,c'"));
  EXPECT_THAT(ReadError("id,class,path\na,c,p,extra\n"),
              HasSubstr("m.csv:2: expected 3 fields as in the header, got 4"));
  EXPECT_THAT(ReadError("id,class,path\n,c,p\n"), HasSubstr("m.csv:2: empty id"));
  EXPECT_THAT(ReadError("id,class,path\na,c,p\nb,,p\n"),
              HasSubstr("m.csv:3: empty class for id 'b'"));
  EXPECT_THAT(ReadError("id,class,path\na,c,  \n"), HasSubstr("m.csv:2: empty path for id 'a'"));
  EXPECT_THAT(ReadError("id,class,path\na,c,p\nb,c,p\n\r\na,d,q\n"),
              HasSubstr("m.csv:5: duplicate id 'a' (first on line 2)"));
  EXPECT_THAT(ReadError("id,class,path\na,\"c,p\n"),
              HasSubstr("m.csv:2: unterminated quoted field starting at column 3"));
  EXPECT_THAT(ReadError("id,class,path\na,\"c\"x,p\n"),
              HasSubstr("m.csv:2: unexpected 'x' after quoted field at column 6"));
  EXPECT_THAT(ReadError("id,class,path\na,c\"d,p\n"),
              HasSubstr("m.csv:2: quote inside unquoted field 'c\"d'"));
}

TEST(ManifestTest, WriteThenReadRoundTripsFieldsThatNeedQuoting) {
  const std::string dir = TestDir();
  const std::vector<ManifestEntry> written = {
      {"a,1", "say \"x\"", "/abs/a.off", 0},
      {" b ", "-1", "/abs/with space.obj", 0},
      {"c", "chair", "/abs/c.ply", 0},
  };
  const std::string path = dir + "/out.csv";
  ASSERT_TRUE(WriteManifest(path, written).ok());
  const auto read = ReadManifest(path);
  ASSERT_TRUE(read.ok()) << read.status();
  ASSERT_EQ(read->size(), written.size());
  for (std::size_t i = 0; i < written.size(); ++i) {
    EXPECT_EQ((*read)[i].id, written[i].id);
    EXPECT_EQ((*read)[i].label, written[i].label);
    EXPECT_EQ((*read)[i].path, written[i].path);
    EXPECT_EQ((*read)[i].line, static_cast<int>(i) + 2);
  }
}

TEST(ManifestTest, WriteKeepsRelativePathsAsGiven) {
  const std::string dir = TestDir();
  const std::string path = dir + "/out.csv";
  ASSERT_TRUE(WriteManifest(path, {{"a", "c", "models/a.off", 0}}).ok());
  std::ifstream in(path);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(text, "id,class,path\na,c,models/a.off\n");
}

TEST(ManifestTest, WriteRejectsEntriesThatWouldNotReadBack) {
  const std::string path = TestDir() + "/out.csv";
  EXPECT_THAT(WriteManifest(path, {{"a", "c", "p", 0}, {"a", "d", "q", 0}}).message(),
              HasSubstr("entries 0 and 1 have the same id 'a'"));
  EXPECT_THAT(WriteManifest(path, {{"a", "", "p", 0}}).message(), HasSubstr("entry 0"));
  EXPECT_THAT(WriteManifest(path, {{"a", "c", "p", 0}, {"b", "c", "line\nbreak", 0}}).message(),
              HasSubstr("entry 1"));
  EXPECT_EQ(WriteManifest(TestDir() + "/no/such/dir/out.csv", {{"a", "c", "p", 0}}).code(),
            absl::StatusCode::kPermissionDenied);
}

}  // namespace
}  // namespace meshseek
