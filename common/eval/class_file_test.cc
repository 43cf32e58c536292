#include "common/eval/class_file.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

namespace meshseek {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;

std::string FixturePath(const std::string& name) {
  const char* root = std::getenv("MESHSEEK_SOURCE_DIR");
  return std::string(root != nullptr ? root : "../..") + "/tests/fixtures/eval/" + name;
}

// A fresh folder under the test temp dir, one per test.
std::string TestDir() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const std::string dir = ::testing::TempDir() + "/class_file_test_" + info->name();
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

// The error message ReadPsbClassFile gives for `text`, or "OK".
std::string ReadError(const std::string& text) {
  const std::string path = TestDir() + "/c.cla";
  std::ofstream(path, std::ios::binary) << text;
  const auto file = ReadPsbClassFile(path);
  return file.ok() ? "OK" : std::string(file.status().message());
}

TEST(ClassFileTest, ReadsHierarchyMiscClassAndModelOrder) {
  const auto file = ReadPsbClassFile(FixturePath("hierarchy.cla"));
  ASSERT_TRUE(file.ok()) << file.status();
  ASSERT_EQ(file->classes.size(), 7u);
  EXPECT_EQ(file->classes[0].name, "vehicle");
  EXPECT_EQ(file->classes[0].parent, kNoParent);
  EXPECT_TRUE(file->classes[0].model_ids.empty());
  EXPECT_EQ(file->classes[1].name, "car");
  EXPECT_EQ(file->classes[1].parent, "vehicle");
  EXPECT_THAT(file->classes[1].model_ids, ElementsAre("10", "11", "12"));
  EXPECT_EQ(file->classes[2].parent, "vehicle");
  EXPECT_EQ(file->classes[4].name, "dog");
  EXPECT_EQ(file->classes[4].parent, "animal");
  EXPECT_EQ(file->classes[5].name, "puppy");
  EXPECT_EQ(file->classes[5].parent, "dog");
  EXPECT_EQ(file->classes[6].name, kMiscClass);
  EXPECT_EQ(file->classes[6].parent, kNoParent);
  EXPECT_THAT(file->model_ids, ElementsAre("10", "11", "12", "20", "21", "30", "31", "40", "41"));
  EXPECT_THAT(file->labels,
              ElementsAre("car", "car", "car", "plane", "plane", "dog", "dog", "-1", "-1"));
}

TEST(ClassFileTest, ToleratesCrlfTabsAndMissingFinalNewline) {
  const std::string path = TestDir() + "/crlf.cla";
  std::ofstream(path, std::ios::binary) << "PSB 1\r\n2\t3\r\n\r\na 0 2\r\n x \r\ny\r\nb a 1\r\nz";
  const auto file = ReadPsbClassFile(path);
  ASSERT_TRUE(file.ok()) << file.status();
  EXPECT_THAT(file->model_ids, ElementsAre("x", "y", "z"));
  EXPECT_THAT(file->labels, ElementsAre("a", "a", "b"));
  EXPECT_EQ(file->classes[1].parent, "a");
}

TEST(ClassFileTest, MissingFileIsNotFoundAndAFolderIsRejected) {
  const std::string dir = TestDir();
  EXPECT_EQ(ReadPsbClassFile(dir + "/absent.cla").status().code(), absl::StatusCode::kNotFound);
  EXPECT_THAT(ReadPsbClassFile(dir).status().message(), HasSubstr(dir + ": is a folder"));
}

TEST(ClassFileTest, AFileLargerThanTheLimitIsRefusedBeforeItIsRead) {
  const std::string path = TestDir() + "/huge.cla";
  std::ofstream(path) << "PSB 1\n";
  std::filesystem::resize_file(path, kMaxClassFileBytes + 1);  // sparse
  const auto file = ReadPsbClassFile(path);
  EXPECT_EQ(file.status().code(), absl::StatusCode::kResourceExhausted);
  EXPECT_THAT(file.status().message(), HasSubstr(path + ": 268435457 bytes, more than the limit"));
}

TEST(ClassFileTest, ParseFromMemoryNamesTheGivenPath) {
  const auto file = ParsePsbClassFile("PSB 1\n1 2\nchair 0 2\nm1\nm2\n", "mem.cla");
  ASSERT_TRUE(file.ok()) << file.status();
  EXPECT_THAT(file->model_ids, ElementsAre("m1", "m2"));
  // Counts in the billions cost nothing: the lines run out first.
  EXPECT_THAT(ParsePsbClassFile("PSB 1\n4000000000 4000000000\nc 0 4000000000\nm1\n", "mem.cla")
                  .status()
                  .message(),
              HasSubstr("mem.cla:4: file ends inside class 'c'"));
}

TEST(ClassFileTest, ErrorsNameFileLineAndValue) {
  EXPECT_THAT(ReadError(""), HasSubstr("c.cla:1: empty file"));
  EXPECT_THAT(ReadError("PSB 2\n1 1\n"), HasSubstr("c.cla:1: expected 'PSB 1', got 'PSB 2'"));
  EXPECT_THAT(ReadError("\nPSB 1\n"), HasSubstr("c.cla:2: file ends after 'PSB 1'"));
  EXPECT_THAT(ReadError("PSB 1\n3\n"),
              HasSubstr("c.cla:2: expected '<numClasses> <numModels>', got '3'"));
  EXPECT_THAT(ReadError("PSB 1\n-1 2\n"), HasSubstr("c.cla:2: expected '<numClasses>"));
  EXPECT_THAT(ReadError("PSB 1\n1 1\n\na 0\nx\n"),
              HasSubstr("c.cla:4: expected class header '<name> <parent> <count>' for class 1 of "
                        "1, got 'a 0'"));
  EXPECT_THAT(ReadError("PSB 1\n1 1\na 0 many\nx\n"), HasSubstr("c.cla:3: expected class header"));
  EXPECT_THAT(ReadError("PSB 1\n1 1\n0 0 1\nx\n"),
              HasSubstr("c.cla:3: class name '0' is reserved"));
  EXPECT_THAT(ReadError("PSB 1\n2 0\na 0 0\n\na 0 0\n"),
              HasSubstr("c.cla:5: class 'a' already declared on line 3"));
  EXPECT_THAT(ReadError("PSB 1\n2 1\nchild parent 1\nx\nparent 0 0\n"),
              HasSubstr("c.cla:3: parent 'parent' of class 'child' is not declared before it"));
  EXPECT_THAT(ReadError("PSB 1\n1 2\na 0 2\nx y\ny\n"),
              HasSubstr("c.cla:4: expected model id 1 of 2 of class 'a' (line 3), got 'x y'"));
  EXPECT_THAT(ReadError("PSB 1\n2 3\na 0 2\nx\ny\nb 0 1\nx\n"),
              HasSubstr("c.cla:7: model id 'x' already listed on line 4"));
  // A class whose count is too small leaves an id where a class header belongs.
  EXPECT_THAT(ReadError("PSB 1\n2 3\na 0 1\nx\ny\nb 0 1\nz\n"),
              HasSubstr("c.cla:5: expected class header '<name> <parent> <count>' for class 2 of "
                        "2, got 'y' (does class 'a' list more models than its count?)"));
  // A class whose count is too large swallows the next header as an id.
  EXPECT_THAT(ReadError("PSB 1\n2 3\na 0 3\nx\ny\nb 0 1\nz\n"),
              HasSubstr("c.cla:6: expected model id 3 of 3 of class 'a' (line 3), got 'b 0 1'"));
  // Truncated files.
  EXPECT_THAT(ReadError("PSB 1\n2 3\na 0 2\nx\ny\n\n"),
              HasSubstr("c.cla:5: file ends after 1 classes; line 2 declares 2"));
  EXPECT_THAT(ReadError("PSB 1\n1 3\na 0 3\nx\ny\n"),
              HasSubstr("c.cla:5: file ends inside class 'a' (line 3), which declares 3 models, "
                        "after 2"));
  // Counts that disagree with the header.
  EXPECT_THAT(ReadError("PSB 1\n1 3\na 0 2\nx\ny\n"),
              HasSubstr("c.cla:2: header declares 3 models, the classes list 2"));
  EXPECT_THAT(ReadError("PSB 1\n1 2\na 0 2\nx\ny\nb 0 0\n"),
              HasSubstr("c.cla:6: unexpected 'b 0 0' after the 1 classes declared on line 2"));
}

TEST(ClassFileTest, WriteThenReadRoundTripsTheHierarchy) {
  const auto original = ReadPsbClassFile(FixturePath("hierarchy.cla"));
  ASSERT_TRUE(original.ok()) << original.status();
  const std::string path = TestDir() + "/out.cla";
  ASSERT_TRUE(WritePsbClassFile(path, *original).ok());
  const auto copy = ReadPsbClassFile(path);
  ASSERT_TRUE(copy.ok()) << copy.status();
  ASSERT_EQ(copy->classes.size(), original->classes.size());
  for (std::size_t c = 0; c < copy->classes.size(); ++c) {
    EXPECT_EQ(copy->classes[c].name, original->classes[c].name);
    EXPECT_EQ(copy->classes[c].parent, original->classes[c].parent);
    EXPECT_EQ(copy->classes[c].model_ids, original->classes[c].model_ids);
  }
  EXPECT_EQ(copy->model_ids, original->model_ids);
  EXPECT_EQ(copy->labels, original->labels);
}

TEST(ClassFileTest, WritesFlatClassesInPsbLayout) {
  ClassFile file;
  file.classes = {{"cup", "", {"m1", "m2"}}, {"-1", "0", {"m3"}}};
  const std::string path = TestDir() + "/flat.cla";
  ASSERT_TRUE(WritePsbClassFile(path, file).ok());
  std::ifstream in(path);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(text, "PSB 1\n2 3\n\ncup 0 2\nm1\nm2\n\n-1 0 1\nm3\n");
}

TEST(ClassFileTest, WriteRejectsWhatCannotBeReadBack) {
  const std::string path = TestDir() + "/bad.cla";
  auto write_error = [&path](const ClassFile& file) {
    return std::string(WritePsbClassFile(path, file).message());
  };
  ClassFile file;
  file.classes = {{"a b", "0", {"x"}}};
  EXPECT_THAT(write_error(file), HasSubstr("class 0 has the invalid name 'a b'"));
  file.classes = {{"a", "0", {"x y"}}};
  EXPECT_THAT(write_error(file), HasSubstr("class 'a' has the invalid model id 'x y'"));
  file.classes = {{"a", "0", {"x"}}, {"b", "0", {"x"}}};
  EXPECT_THAT(write_error(file), HasSubstr("model id 'x' appears twice"));
  file.classes = {{"a", "0", {"x"}}, {"a", "0", {"y"}}};
  EXPECT_THAT(write_error(file), HasSubstr("class 'a' appears twice"));
  file.classes = {{"a", "b", {"x"}}, {"b", "0", {"y"}}};
  EXPECT_THAT(write_error(file), HasSubstr("parent 'b' of class 'a' is not a class declared"));
  // Flattened views that disagree with the classes would misstate the matrix order.
  file.classes = {{"a", "0", {"x"}}, {"b", "0", {"y"}}};
  file.model_ids = {"y", "x"};
  EXPECT_THAT(write_error(file),
              HasSubstr("model 0 is 'x' of class 'a' in the class list but 'y' of class 'a'"));
  file.model_ids = {"x"};
  EXPECT_THAT(write_error(file), HasSubstr("the classes list 2 models but model_ids has 1"));
}

TEST(ClassFileTest, MakeFlatClassFileKeepsOrderAndNeedsContiguousClasses) {
  const auto file = MakeFlatClassFile({"a", "b", "c", "d"}, {"x", "x", "-1", "y"});
  ASSERT_TRUE(file.ok()) << file.status();
  ASSERT_EQ(file->classes.size(), 3u);
  EXPECT_THAT(file->classes[0].model_ids, ElementsAre("a", "b"));
  EXPECT_EQ(file->classes[1].name, "-1");
  EXPECT_EQ(file->classes[2].parent, kNoParent);
  EXPECT_THAT(file->model_ids, ElementsAre("a", "b", "c", "d"));
  EXPECT_TRUE(WritePsbClassFile(TestDir() + "/flat.cla", *file).ok());

  EXPECT_THAT(MakeFlatClassFile({"a", "b", "c"}, {"x", "y", "x"}).status().message(),
              HasSubstr("model 2 ('c') of class 'x' is separated"));
  EXPECT_THAT(MakeFlatClassFile({"a"}, {"x", "y"}).status().message(),
              HasSubstr("got 1 model ids and 2 labels"));
}

}  // namespace
}  // namespace meshseek
