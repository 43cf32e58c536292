#include "common/eval/evaluation_report.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_replace.h"
#include "common/base/file_io.h"
#include "common/base/json.h"
#include "common/eval/distance_matrix.h"
#include "common/eval/report_html.h"
#include "common/geometry/mesh_io.h"
#include "common/geometry/test_meshes.h"

namespace meshseek {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

// A fresh folder per test.
std::string TestDir() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const std::string dir = ::testing::TempDir() + "/evaluation_report_test_" + info->name();
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

// Seven models: three cubes, three spheres (one of whose mesh files is
// missing) and a misc model; distances that mostly rank a model's own class
// first. Writes what `meshseek eval` writes into `dir`.
std::vector<ManifestEntry> WriteRun(const std::string& dir) {
  EXPECT_TRUE(WriteMesh(dir + "/cube.off", testing_meshes::Cube()).ok());
  EXPECT_TRUE(WriteMesh(dir + "/sphere.off", testing_meshes::Icosphere(2)).ok());
  std::vector<ManifestEntry> models;
  const char* labels[] = {"cube", "cube", "cube", "sphere", "sphere", "sphere", "-1"};
  for (int i = 0; i < 7; ++i) {
    const std::string mesh = i < 3 ? "/cube.off" : (i == 5 ? "/gone.off" : "/sphere.off");
    models.push_back({absl::StrCat("m", i), labels[i], dir + mesh});
  }
  EXPECT_TRUE(WriteManifest(dir + "/models.csv", models).ok());
  std::vector<float> d(49);
  for (int i = 0; i < 7; ++i) {
    for (int j = 0; j < 7; ++j) {
      d[i * 7 + j] = i == j ? 0 : (labels[i] == std::string(labels[j]) ? 1 : 2) + 0.01f * (i + j);
    }
  }
  d[0 * 7 + 6] = 0.5f;  // the misc model is cube m0's nearest: a miss
  EXPECT_TRUE(WriteDistanceMatrix(dir + "/distances.bin", d, 7).ok());
  std::vector<std::string> label_list(std::begin(labels), std::end(labels));
  auto metrics = EvaluateRetrieval(label_list, d);
  EXPECT_TRUE(metrics.ok());
  Json json = MetricsToJson(*metrics);
  json.Set("models", 7);
  Json& params = json.Set("parameters", Json::MakeObject());
  params.Set("method", "dld");
  params.Set("vocabulary", 150);
  json.Set("timings_seconds", Json::MakeObject()).Set("total", 12.345);
  EXPECT_TRUE(WriteStringToFile(dir + "/metrics.json", json.Dump()).ok());
  return models;
}

EvaluationReportOptions SmallOptions() {
  EvaluationReportOptions options;
  options.thumbnail.size = 32;
  options.num_threads = 2;
  return options;
}

TEST(EvaluationReportOptionsTest, DefaultsAreValid) {
  EXPECT_TRUE(EvaluationReportOptions().Validate().ok());
  EvaluationReportOptions options;
  options.top_results = 0;
  EXPECT_THAT(std::string(options.Validate().message()), HasSubstr("top_results"));
}

TEST(EvaluationReportTest, OnePageWithTheMetricsEvalPrintedCurvesAndPictures) {
  const std::string dir = TestDir();
  WriteRun(dir);
  auto run = ReadEvaluationRun(dir);
  ASSERT_TRUE(run.ok()) << run.status();
  auto report = ComputeEvaluationReport(*run, SmallOptions());
  ASSERT_TRUE(report.ok()) << report.status();
  EXPECT_EQ(report->metrics.queries, 6u);
  EXPECT_EQ(report->class_sizes.at("-1"), 1u);
  // One sample per query class, each with the other 6 models as results
  // (fewer than top_results), best first.
  ASSERT_EQ(report->samples.size(), 2u);
  EXPECT_EQ(report->samples[0].results.size(), 6u);
  EXPECT_EQ(report->thumbnails.size(), 7u);
  EXPECT_TRUE(report->thumbnails.at(5).png.empty());
  EXPECT_THAT(report->thumbnails.at(5).error, HasSubstr("gone.off"));
  EXPECT_FALSE(report->thumbnails.at(0).png.empty());

  auto html = EvaluationReportHtml(*report);
  ASSERT_TRUE(html.ok()) << html.status();
  EXPECT_THAT(*html, HasSubstr("<!DOCTYPE html>"));
  EXPECT_THAT(*html, HasSubstr("Retrieval evaluation: dld"));
  EXPECT_THAT(*html, HasSubstr("<svg"));
  EXPECT_THAT(*html, HasSubstr("data:image/png;base64,iVBORw0KGgo"));
  EXPECT_THAT(*html, HasSubstr("no preview"));  // the missing mesh
  EXPECT_THAT(*html, HasSubstr("tile miss"));
  EXPECT_THAT(*html, HasSubstr("tile hit"));
  EXPECT_THAT(*html, HasSubstr("<dt>vocabulary</dt><dd>150</dd>"));
  EXPECT_THAT(*html, HasSubstr("12.3 s"));
  // Self-contained: nothing fetched from elsewhere, no script.
  EXPECT_THAT(*html, Not(HasSubstr("<script")));
  EXPECT_THAT(*html, Not(HasSubstr("src=\"http")));
  EXPECT_THAT(*html, Not(HasSubstr("href")));
  EXPECT_THAT(*html, Not(HasSubstr("url(")));
  // Every figure of eval's table, as eval printed it.
  std::istringstream table(FormatMetricsTable(report->metrics));
  std::string line;
  int values = 0;
  while (std::getline(table, line)) {
    std::istringstream fields(line);
    std::string name, value;
    fields >> name;
    if (name != "micro" && name != "macro") continue;
    while (fields >> value) {
      EXPECT_THAT(*html, HasSubstr("<td>" + value + "</td>")) << name;
      ++values;
    }
  }
  EXPECT_EQ(values, 14);
}

TEST(EvaluationReportTest, MissingOrInconsistentFilesAreNamed) {
  const std::string dir = TestDir();
  WriteRun(dir);
  std::filesystem::remove(dir + "/models.csv");
  auto run = ReadEvaluationRun(dir);
  EXPECT_EQ(run.status().code(), absl::StatusCode::kNotFound);
  EXPECT_THAT(std::string(run.status().message()), HasSubstr(dir + "/models.csv: not found"));

  WriteRun(dir);
  std::filesystem::resize_file(dir + "/distances.bin", 48 * 4);
  run = ReadEvaluationRun(dir);
  EXPECT_THAT(std::string(run.status().message()), HasSubstr("distances.bin"));
  EXPECT_THAT(std::string(run.status().message()), HasSubstr("lists 7 models"));

  WriteRun(dir);
  auto json = ReadFileToString(dir + "/metrics.json");
  ASSERT_TRUE(json.ok());
  ASSERT_TRUE(WriteStringToFile(dir + "/metrics.json",
                                absl::StrReplaceAll(*json, {{"\"models\": 7", "\"models\": 8"}}))
                  .ok());
  run = ReadEvaluationRun(dir);
  EXPECT_THAT(std::string(run.status().message()), HasSubstr("counts 8 models"));

  // A matrix from another run: the recomputed metrics disagree.
  WriteRun(dir);
  std::vector<float> other(49, 1.0f);
  for (int i = 0; i < 7; ++i) other[i * 7 + i] = 0;
  ASSERT_TRUE(WriteDistanceMatrix(dir + "/distances.bin", other, 7).ok());
  run = ReadEvaluationRun(dir);
  ASSERT_TRUE(run.ok()) << run.status();
  auto report = ComputeEvaluationReport(*run, SmallOptions());
  EXPECT_EQ(report.status().code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_THAT(std::string(report.status().message()), HasSubstr("not from the same"));
}

}  // namespace
}  // namespace meshseek
