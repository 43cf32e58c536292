// End to end on the built-in synthetic benchmark: the in-process pipeline, the
// `meshseek` CLI as a user runs it, and the independent evaluator.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "common/base/file_io.h"
#include "common/base/test_env.h"
#include "common/eval/distance_matrix.h"
#include "common/pipeline/collection_evaluation.h"
#include "common/synth/synthetic_benchmark.h"

namespace meshseek {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

// Small but real settings: every class of the benchmark, fewer points and
// words than the defaults so the suite stays quick.
RetrievalPipelineOptions SmallOptions() {
  RetrievalPipelineOptions options;
  options.extractor.dld.num_points = 256;
  options.kmeans.num_centroids = 150;
  options.num_threads = 2;
  return options;
}

// The synthetic benchmark's 9 classes, 8 models each; under a sanitizer 4
// each (common/base/test_env.h): the same paths run on half the models.
constexpr int kModelsPerClass = kSanitized ? 4 : 8;
constexpr std::size_t kModels = 9 * kModelsPerClass;

class EndToEndTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new std::string(::testing::TempDir() + "/meshseek_e2e");
    std::filesystem::remove_all(*dir_);
    // The CLI's embedded stack keeps collections (and their features) here:
    // start clean so that no run reuses features of an older build.
    std::filesystem::remove_all(::testing::TempDir() + "/meshseek-data");
    SyntheticBenchmarkOptions benchmark;
    benchmark.models_per_class = kModelsPerClass;
    ASSERT_TRUE(GenerateSyntheticBenchmark(benchmark, *dir_ + "/bench").ok());
  }
  static void TearDownTestSuite() { delete dir_; }
  static std::string* dir_;
};
std::string* EndToEndTest::dir_ = nullptr;

// Runs a shell command, returning its exit code and combined output.
int RunCommand(const std::string& command, std::string* output) {
  // In the suite's temporary folder: the CLI's embedded stack keeps its state
  // in ./meshseek-data.
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

TEST_F(EndToEndTest, PipelineRanksSyntheticClassesWellAboveChance) {
  auto models = ReadManifest(*dir_ + "/bench/manifest.csv");
  ASSERT_TRUE(models.ok()) << models.status();
  ASSERT_EQ(models->size(), kModels);
  auto evaluation = EvaluateCollection(*models, CollectionOptions::Of(SmallOptions()));
  ASSERT_TRUE(evaluation.ok()) << evaluation.status();
  // Chance first tier is 7/71 (10 %; 3/35 under a sanitizer). The shapes are built to be told apart by
  // local surface shape, with soups, several components and sparse and dense
  // tessellations in every class.
  EXPECT_GT(evaluation->metrics.micro.rp_excl, 0.6);
  EXPECT_GT(evaluation->metrics.micro.nn, 0.8);
  EXPECT_EQ(evaluation->metrics.queries, kModels);
  for (std::size_t n : evaluation->methods[0].features_per_model) EXPECT_GT(n, 400u);

  // The same run twice gives the same matrix: extraction, k-means and ranking
  // are deterministic whatever the thread count.
  RetrievalPipelineOptions one_thread = SmallOptions();
  one_thread.num_threads = 1;
  auto again = EvaluateCollection(*models, CollectionOptions::Of(one_thread));
  ASSERT_TRUE(again.ok());
  EXPECT_EQ(again->distances, evaluation->distances);
}

TEST_F(EndToEndTest, CliEvalWritesMatrixAndMetricsThatTheReferenceEvaluatorAgreesWith) {
  const std::string out = *dir_ + "/eval";
  std::string output;
  const int code =
      RunCommand(std::string(MESHSEEK_CLI_PATH) + " eval --manifest " + *dir_ +
                     "/bench/manifest.csv --method dld --points 256 --vocabulary 150 --out " + out,
                 &output);
  ASSERT_EQ(code, 0) << output;
  EXPECT_THAT(output, HasSubstr("RP_excl"));
  EXPECT_THAT(output, HasSubstr("micro"));
  auto matrix = ReadDistanceMatrix(out + "/distances.bin", kModels);
  ASSERT_TRUE(matrix.ok()) << matrix.status();
  for (std::size_t i = 0; i < kModels; ++i) EXPECT_EQ((*matrix)[i * kModels + i], 0.0f);
  auto json = ReadFileToString(out + "/metrics.json");
  ASSERT_TRUE(json.ok());
  EXPECT_THAT(*json, HasSubstr("\"RP_excl\""));
  EXPECT_THAT(*json, HasSubstr("\"scale\""));
  EXPECT_THAT(*json, HasSubstr("\"vocabulary\": 150"));

  const std::string evaluator =
      std::string(std::getenv("MESHSEEK_SOURCE_DIR")) + "/../shared/tools/psb_eval.py";
  if (!std::filesystem::exists(evaluator)) GTEST_SKIP() << evaluator << " not present";
  std::string reference;
  ASSERT_EQ(RunCommand("python3 " + evaluator + " " + *dir_ + "/bench/manifest.csv " + out +
                           "/distances.bin",
                       &reference),
            0)
      << reference;
  // psb_eval.py prints the same table as meshseek (one decimal, same layout).
  std::istringstream lines(reference);
  std::string line;
  int matched = 0;
  while (std::getline(lines, line)) {
    if (line.find("micro") != std::string::npos || line.find("macro") != std::string::npos) {
      EXPECT_THAT(output, HasSubstr(line));
      ++matched;
    }
  }
  EXPECT_EQ(matched, 2);
}

TEST_F(EndToEndTest, EveryMethodRunsThroughTheCliWithTheSameOutputs) {
  // LD-SIFT and RLD-SIFT behind the same interface as DLD-SIFT (small
  // settings: the point here is the plumbing; accuracy is measured in bench/).
  for (const std::string method : {"ld", "rld"}) {
    const std::string out = *dir_ + "/eval_" + method;
    std::string output;
    const int code = RunCommand(
        std::string(MESHSEEK_CLI_PATH) + " eval --progress=false --manifest " + *dir_ +
            "/bench/manifest.csv --method " + method +
            (method == "rld" ? " --rld_samples 3000" : "") + " --vocabulary 100 --out " + out,
        &output);
    ASSERT_EQ(code, 0) << output;
    EXPECT_THAT(output, HasSubstr("RP_excl"));
    EXPECT_TRUE(ReadDistanceMatrix(out + "/distances.bin", kModels).ok());
    auto json = ReadFileToString(out + "/metrics.json");
    ASSERT_TRUE(json.ok());
    EXPECT_THAT(*json, HasSubstr("\"method\": \"" + method + "\""));
    EXPECT_THAT(*json, HasSubstr("\"models_without_features\""));
    // The flags' defaults are each method's own measured scale factor (a
    // shared --scale_factor default once gave LD-SIFT RLD-SIFT's).
    EXPECT_THAT(*json, HasSubstr(method == "ld" ? "\"scale_factor\": 20" : "\"scale_factor\": 15"));
  }
}

TEST_F(EndToEndTest, CliInspectWritesPointsAndPictures) {
  const std::string out = *dir_ + "/inspect";
  std::string output;
  const int code =
      RunCommand(std::string(MESHSEEK_CLI_PATH) + " inspect " + *dir_ +
                     "/bench/models/20.off --method rld --rld_samples 3000 --out " + out,
                 &output);
  ASSERT_EQ(code, 0) << output;
  EXPECT_THAT(output, HasSubstr("level 1:"));
  for (const std::string file : {"points.ply", "points.png", "depth_images.png"}) {
    EXPECT_GT(std::filesystem::file_size(out + "/" + file), 100u) << file;
  }
  auto ply = ReadFileToString(out + "/points.ply");
  ASSERT_TRUE(ply.ok());
  EXPECT_THAT(*ply, HasSubstr("property int level"));
}

TEST_F(EndToEndTest, CliNamesTheModelAndLineOfABadMeshAndFailsCleanly) {
  const std::string dir = *dir_ + "/bad";
  std::filesystem::create_directories(dir);
  std::ofstream(dir + "/ok.off") << "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  std::ofstream(dir + "/broken.off") << "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n";
  std::ofstream(dir + "/manifest.csv") << "id,class,path\na,x,ok.off\nb,x,broken.off\nc,x,ok.off\n";
  std::string output;
  const int code =
      RunCommand(std::string(MESHSEEK_CLI_PATH) + " eval --method dld --progress=false --manifest " +
                     dir + "/manifest.csv --out " + dir + "/out",
                 &output);
  EXPECT_NE(code, 0);
  EXPECT_THAT(output, HasSubstr("model 'b' (manifest line 3)"));
  EXPECT_THAT(output, HasSubstr("broken.off: face 0 (0-based) references vertex 7"));
  EXPECT_FALSE(std::filesystem::exists(dir + "/out/distances.bin"));
}

// Ingest into an existing collection takes its parameters: method flags only
// say how to create one, a conflicting or inapplicable flag is an error
// naming it, and a model added after the build is searchable (status counts
// it) with no build.
// `meshseek serve` on a data folder, in the background for the object's
// lifetime: commands then name it with --server, as a user's would, and run
// no services of their own.
class Served {
 public:
  explicit Served(const std::string& data_dir) {
    const std::string command = "sh -c 'echo $$; exec " + std::string(MESHSEEK_CLI_PATH) +
                                " serve --port 0 --data_dir " + data_dir + "' 2>/dev/null";
    pipe_ = popen(command.c_str(), "r");
    char line[512];
    if (pipe_ != nullptr && fgets(line, sizeof line, pipe_) != nullptr) pid_ = std::atoi(line);
    // "meshseek serving on 127.0.0.1:PORT (data in ...); Ctrl-C stops"
    if (pid_ > 0 && fgets(line, sizeof line, pipe_) != nullptr) {
      std::istringstream words(line);
      std::string word;
      while (words >> word && word != "on") {
      }
      words >> address_;
    }
  }
  ~Served() {
    if (pid_ > 0) kill(pid_, SIGTERM);
    if (pipe_ != nullptr) pclose(pipe_);
  }
  // host:port, empty when it did not start.
  const std::string& address() const { return address_; }

 private:
  FILE* pipe_ = nullptr;
  int pid_ = 0;
  std::string address_;
};

TEST_F(EndToEndTest, CliIngestIntoAnExistingCollectionKeepsItsParameters) {
  const std::string dir = *dir_ + "/grow";
  std::filesystem::create_directories(dir);
  std::ifstream all(*dir_ + "/bench/manifest.csv");
  std::string line;
  std::getline(all, line);
  std::ofstream first(dir + "/first.csv"), later(dir + "/later.csv");
  first << line << "\n";
  later << line << "\n";
  for (int i = 0; i < 9 && std::getline(all, line); ++i) {
    // Paths relative to the benchmark's folder.
    const std::size_t comma = line.rfind(',');
    const std::string row = line.substr(0, comma + 1) + *dir_ + "/bench/" + line.substr(comma + 1);
    (i < 8 ? first : later) << row << "\n";
  }
  first.close();
  later.close();
  const auto command = [&](const std::string& verb) {
    return std::string(MESHSEEK_CLI_PATH) + " " + verb + " --progress=false --data_dir " + dir +
           "/data --collection grow ";
  };
  std::string output;
  ASSERT_EQ(RunCommand(command("ingest") + "--manifest " + dir + "/first.csv --method lsf "
                                           "--vocabulary 16",
                       &output),
            0)
      << output;
  ASSERT_EQ(RunCommand(command("build"), &output), 0) << output;
  // Exit code 2: a usage error, as for any bad flag.
  EXPECT_EQ(RunCommand(command("ingest") + "--manifest " + dir + "/later.csv --method dld", &output),
            2);
  EXPECT_THAT(output, HasSubstr("--method dld (it has method=lsf)"));
  EXPECT_EQ(
      RunCommand(command("ingest") + "--manifest " + dir + "/later.csv --rld.vocabulary 9", &output),
      2);
  EXPECT_THAT(output, HasSubstr("collection 'grow' exists with other parameters"));
  EXPECT_THAT(output, HasSubstr("rld.vocabulary"));
  // Without flags, or with flags that agree, its own parameters apply.
  ASSERT_EQ(RunCommand(command("ingest") + "--manifest " + dir + "/later.csv --vocabulary 16",
                       &output),
            0)
      << output;
  // What scripts read (protobuf's JSON mapping: uint64 counts are strings),
  // with the canonical parameters alone: no legacy field, zeroed or not; of
  // a running server, as scripts ask.
  const Served served(dir + "/data");
  ASSERT_FALSE(served.address().empty());
  const std::string status = std::string(MESHSEEK_CLI_PATH) + " status --format json --server " +
                             served.address();
  ASSERT_EQ(RunCommand(status + " --collection grow", &output), 0) << output;
  EXPECT_THAT(output, HasSubstr("\"indexed\":\"9\""));
  EXPECT_THAT(output, HasSubstr("\"added_since_build\":\"1\""));
  EXPECT_THAT(output, HasSubstr("{\"name\":\"method\",\"value\":\"lsf\"}"));
  EXPECT_THAT(output, Not(HasSubstr("FEATURE_METHOD_UNSPECIFIED")));
  EXPECT_THAT(output, Not(HasSubstr("\"kl_epsilon\":0")));
  EXPECT_THAT(output, Not(HasSubstr("\"vocabulary\":0")));
  // `status` naming nothing lists the collections.
  ASSERT_EQ(RunCommand(status, &output), 0) << output;
  EXPECT_THAT(output, HasSubstr("{\"collections\":[{\"name\":\"grow\""));
}

TEST_F(EndToEndTest, CliRejectsBadFlagsWithAClearMessage) {
  std::string output;
  EXPECT_EQ(RunCommand(std::string(MESHSEEK_CLI_PATH) + " eval --out /tmp/x", &output), 2);
  EXPECT_THAT(output, HasSubstr("eval needs --manifest FILE"));
  EXPECT_EQ(RunCommand(std::string(MESHSEEK_CLI_PATH) + " eval --manifest " + *dir_ +
                           "/bench/manifest.csv --out /tmp/x --method sift3d",
                       &output),
            2);
  EXPECT_THAT(output, HasSubstr("parameter method: 'sift3d' is not one of dld, rld, ld"));
  EXPECT_EQ(RunCommand(std::string(MESHSEEK_CLI_PATH) + " eval --method dld --manifest " + *dir_ +
                           "/bench/manifest.csv --out /tmp/x --scale -1",
                       &output),
            2);
  EXPECT_THAT(output, HasSubstr("parameter scale: '-1' is not a number in [1e-06, 2]"));
  EXPECT_EQ(RunCommand(std::string(MESHSEEK_CLI_PATH) + " frobnicate", &output), 2);
  EXPECT_THAT(output, HasSubstr("unknown command 'frobnicate'"));
  EXPECT_EQ(
      RunCommand(std::string(MESHSEEK_CLI_PATH) +
                     " eval --method dld --manifest /nonexistent.csv --out /tmp/x",
                 &output),
      1);
  EXPECT_THAT(output, HasSubstr("/nonexistent.csv"));
}

}  // namespace
}  // namespace meshseek
