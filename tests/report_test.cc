// `meshseek report` as a user runs it: synth a small benchmark, evaluate it
// in process, write the report, and check that the page carries what eval
// printed, the plots and the pictures; and that a broken eval folder is
// refused naming the file.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <sstream>
#include <string>

#include "common/base/file_io.h"

namespace meshseek {
namespace {

using ::testing::HasSubstr;

// Runs a shell command in the test's temporary folder, returning its exit
// code and combined output.
int RunCommand(const std::string& command, std::string* output) {
  const std::string full = "cd " + ::testing::TempDir() + " && " + command + " 2>&1";
  FILE* pipe = popen(full.c_str(), "r");
  if (pipe == nullptr) return -1;
  char buffer[4096];
  std::size_t n;
  output->clear();
  while ((n = fread(buffer, 1, sizeof buffer, pipe)) > 0) output->append(buffer, n);
  const int status = pclose(pipe);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

const std::string kCli = MESHSEEK_CLI_PATH;

TEST(ReportCliTest, SynthEvalReport) {
  const std::string dir = ::testing::TempDir() + "/meshseek_report_cli";
  std::filesystem::remove_all(dir);
  std::string output;
  ASSERT_EQ(RunCommand(kCli + " synth --models_per_class 4 --out " + dir + "/bench", &output), 0)
      << output;
  // Small DLD-SIFT settings: the point is the plumbing, not the accuracy.
  ASSERT_EQ(RunCommand(kCli + " eval --server in-process --progress=false --threads 2 --manifest " +
                           dir + "/bench/manifest.csv --method dld --points 128 --vocabulary 40 " +
                           "--out " + dir + "/eval",
                       &output),
            0)
      << output;
  const std::string eval_output = output;
  ASSERT_TRUE(std::filesystem::exists(dir + "/eval/models.csv"));

  ASSERT_EQ(RunCommand(kCli + " report --threads 2 --eval " + dir + "/eval --out " + dir +
                           "/report.html --sample_queries 3 --top_results 4 --thumbnail_size 48",
                       &output),
            0)
      << output;
  EXPECT_THAT(output, HasSubstr("report.html"));
  auto html = ReadFileToString(dir + "/report.html");
  ASSERT_TRUE(html.ok()) << html.status();
  EXPECT_THAT(*html, HasSubstr("<svg"));
  EXPECT_THAT(*html, HasSubstr("data:image/png;base64,"));
  EXPECT_THAT(*html, HasSubstr("Retrieval evaluation: dld"));
  // Every figure of the micro and macro rows that eval printed.
  std::istringstream lines(eval_output);
  std::string line;
  int values = 0;
  while (std::getline(lines, line)) {
    std::istringstream fields(line);
    std::string name, value;
    fields >> name;
    if (name != "micro" && name != "macro") continue;
    while (fields >> value) {
      EXPECT_THAT(*html, HasSubstr("<td>" + value + "</td>")) << name;
      ++values;
    }
  }
  EXPECT_EQ(values, 14) << eval_output;

  // Without --out the report goes beside the eval files.
  ASSERT_EQ(RunCommand(kCli + " report --sample_queries 0 --eval " + dir + "/eval", &output), 0)
      << output;
  EXPECT_TRUE(std::filesystem::exists(dir + "/eval/report.html"));

  // A truncated matrix is refused, naming the file.
  std::filesystem::copy(dir + "/eval", dir + "/broken", std::filesystem::copy_options::recursive);
  std::filesystem::resize_file(dir + "/broken/distances.bin", 100);
  EXPECT_EQ(RunCommand(kCli + " report --eval " + dir + "/broken", &output), 2);
  EXPECT_THAT(output, HasSubstr(dir + "/broken/distances.bin"));
  std::filesystem::remove(dir + "/broken/models.csv");
  EXPECT_EQ(RunCommand(kCli + " report --eval " + dir + "/broken", &output), 1);
  EXPECT_THAT(output, HasSubstr(dir + "/broken/models.csv: not found"));
  EXPECT_EQ(RunCommand(kCli + " report", &output), 2);
  EXPECT_THAT(output, HasSubstr("--eval"));
}

}  // namespace
}  // namespace meshseek
