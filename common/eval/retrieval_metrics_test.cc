#include "common/eval/retrieval_metrics.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <string>

#include "common/eval/distance_matrix.h"
#include "common/eval/manifest.h"

namespace meshseek {
namespace {

using ::testing::HasSubstr;

constexpr double kInf = std::numeric_limits<double>::infinity();

std::string FixturePath(const std::string& name) {
  const char* root = std::getenv("MESHSEEK_SOURCE_DIR");
  return std::string(root != nullptr ? root : "../..") + "/tests/fixtures/eval/" + name;
}

std::string ReadText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// Row-major float matrix from rows written as doubles, for readable test cases.
std::vector<float> Matrix(const std::vector<std::vector<double>>& rows) {
  std::vector<float> m;
  for (const auto& row : rows) {
    for (const double d : row) m.push_back(static_cast<float>(d));
  }
  return m;
}

void ExpectScores(const RetrievalScores& s,
                  double nn,
                  double ft,
                  double st,
                  double e,
                  double dcg,
                  double rp_incl,
                  const std::string& what) {
  SCOPED_TRACE(what);
  EXPECT_NEAR(s.nn, nn, 1e-12);
  EXPECT_NEAR(s.first_tier, ft, 1e-12);
  EXPECT_NEAR(s.second_tier, st, 1e-12);
  EXPECT_NEAR(s.e_measure, e, 1e-12);
  EXPECT_NEAR(s.dcg, dcg, 1e-12);
  EXPECT_NEAR(s.rp_excl, ft, 1e-12);  // R-precision with the query left out is the first tier
  EXPECT_NEAR(s.rp_incl, rp_incl, 1e-12);
}

// Six models, classes A = {0,1,2} and B = {3,4,5}: C = 3, k = C-1 = 2 relevant
// models per query, N-1 = 5 ranked, so E looks at the top min(32, 5) = 5 and,
// with both hits always there, E = 2*2/(5+2) = 4/7 for every query. The DCG
// ideal is 1 + 1/log2(2) = 2. Rankings below list (model, class) by rank.
const std::vector<std::string> kSixLabels = {"A", "A", "A", "B", "B", "B"};
const std::vector<float> kSixDistances = Matrix({
    // q0: 1(A) 3(B) 2(A) 4(B) 5(B)              hits at ranks 1, 3
    {0, 1, 3, 2, 4, 5},
    // q1: 3(B) 4(B) 0(A) 2(A) 5(B)              hits at ranks 3, 4
    {3, 0, 4, 1, 2, 5},
    // q2: 5(B) 0(A) 3(B) 1(A) 4(B); 0 and 3 tie at 1, 1 and 4 at 2: lower index first.
    //                                           hits at ranks 2, 4
    {1, 2, 0, 1, 2, 0.5},
    // q3: 5(B) 0(A) 1(A) 2(A) 4(B); 4 is infinitely far.   hits at ranks 1, 5
    {1, 1, 1, 0, kInf, 0},
    // q4: all tie, so by index: 0 1 2 3(B) 5(B)  hits at ranks 4, 5
    {7, 7, 7, 7, 7, 7},
    // q5: 3(B) 4(B) 0 1 2                       hits at ranks 1, 2
    {1, 1, 1, 0.1, 0.2, 0},
});

TEST(RetrievalMetricsTest, HandComputedScoresForEachQuery) {
  const auto m = EvaluateRetrieval(kSixLabels, kSixDistances);
  ASSERT_TRUE(m.ok()) << m.status();
  ASSERT_EQ(m->per_query.size(), 6u);
  const double l3 = 1 / std::log2(3.0), l5 = 1 / std::log2(5.0);
  const double e = 4.0 / 7;
  //                                           NN FT   ST   E  DCG              RP_incl
  ExpectScores(m->per_query[0].scores, 1, 0.5, 1.0, e, (1 + l3) / 2, 2.0 / 3, "q0");
  ExpectScores(m->per_query[1].scores, 0, 0.0, 1.0, e, (l3 + 0.5) / 2, 1.0 / 3, "q1");
  ExpectScores(m->per_query[2].scores, 0, 0.5, 1.0, e, (1 + 0.5) / 2, 2.0 / 3, "q2");
  ExpectScores(m->per_query[3].scores, 1, 0.5, 0.5, e, (1 + l5) / 2, 2.0 / 3, "q3");
  ExpectScores(m->per_query[4].scores, 0, 0.0, 0.5, e, (0.5 + l5) / 2, 1.0 / 3, "q4");
  ExpectScores(m->per_query[5].scores, 1, 1.0, 1.0, e, 1.0, 1.0, "q5");
  for (std::size_t q = 0; q < 6; ++q) EXPECT_EQ(m->per_query[q].model, q);

  // Both classes have three queries, so micro and macro agree here.
  // DCG sums: A (3 + 2 l3) / 2, B (3.5 + 2 l5) / 2.
  EXPECT_EQ(m->queries, 6u);
  EXPECT_EQ(m->classes, 2u);
  const double dcg = ((3 + 2 * l3) / 2 + (3.5 + 2 * l5) / 2) / 6;
  ExpectScores(m->micro, 0.5, 2.5 / 6, 5.0 / 6, e, dcg, 11.0 / 18, "micro");
  ExpectScores(m->macro, 0.5, 2.5 / 6, 5.0 / 6, e, dcg, 11.0 / 18, "macro");
  ASSERT_EQ(m->per_class.size(), 2u);
  EXPECT_EQ(m->per_class[0].first, "A");
  ExpectScores(m->per_class[0].second, 1.0 / 3, 1.0 / 3, 1, e, (3 + 2 * l3) / 6, 5.0 / 9, "A");
  EXPECT_EQ(m->per_class[1].first, "B");
  ExpectScores(m->per_class[1].second, 2.0 / 3, 0.5, 2.0 / 3, e, (3.5 + 2 * l5) / 6, 2.0 / 3, "B");
}

// Ten models: A = {0,1,2} ranked perfectly, B = {3,4,5,6} ranked last, a class
// of two {7,8} and a misc model {9}. Only A and B models are queries; the pair
// and the misc model are ranked (and count as misses) but never ask.
TEST(RetrievalMetricsTest, SmallAndMiscClassesStayInTheDatabaseButAreNotQueries) {
  const std::vector<std::string> labels = {"A", "A", "A", "B", "B", "B", "B", "pair", "pair", "-1"};
  std::vector<std::vector<double>> rows(10, std::vector<double>(10, 0.0));
  for (std::size_t i = 0; i < 10; ++i) {
    for (std::size_t j = 0; j < 10; ++j) {
      if (labels[i] == "A") rows[i][j] = labels[j] == "A" ? 1 : 5;
      if (labels[i] == "B") rows[i][j] = labels[j] == "B" ? 9 : 2;
    }
  }
  const auto m = EvaluateRetrieval(labels, Matrix(rows));
  ASSERT_TRUE(m.ok()) << m.status();
  EXPECT_EQ(m->queries, 7u);
  EXPECT_EQ(m->classes, 2u);
  ASSERT_EQ(m->per_query.size(), 7u);
  EXPECT_EQ(m->per_query.back().model, 6u);

  // N-1 = 9 ranked, E over the top 9. A (k = 2): perfect, E = 2*2/(9+2) = 4/11.
  // B (k = 3): the 6 others first, hits at ranks 7, 8, 9: E = 2*3/(9+3) = 1/2,
  // DCG = (1/log2 7 + 1/log2 8 + 1/log2 9) / (1 + 1 + 1/log2 3), RP_incl = 1/4.
  const double dcg_b =
      (1 / std::log2(7.0) + 1 / std::log2(8.0) + 1 / std::log2(9.0)) / (2 + 1 / std::log2(3.0));
  ExpectScores(m->per_class[0].second, 1, 1, 1, 4.0 / 11, 1, 1, "A");
  ExpectScores(m->per_class[1].second, 0, 0, 0, 0.5, dcg_b, 0.25, "B");
  // Micro weighs the 3 A and 4 B queries; macro weighs the two classes equally.
  ExpectScores(
      m->micro, 3.0 / 7, 3.0 / 7, 3.0 / 7, 34.0 / 77, (3 + 4 * dcg_b) / 7, 4.0 / 7, "micro");
  ExpectScores(m->macro, 0.5, 0.5, 0.5, 19.0 / 44, (1 + dcg_b) / 2, 0.625, "macro");
}

TEST(RetrievalMetricsTest, EMeasureLooksAtTheTopThirtyTwoOnly) {
  // 40 models: A = {0,1,2}, the rest misc. Query 0 finds 1 first and 2 last
  // (rank 39): top 32 hold 1 of k = 2 hits, so E = 2*1/(32+2) = 1/17.
  std::vector<std::string> labels(40, "-1");
  labels[0] = labels[1] = labels[2] = "A";
  std::vector<std::vector<double>> rows(40, std::vector<double>(40, 1.0));
  rows[0][1] = 0;
  rows[0][2] = 100;
  const auto m = EvaluateRetrieval(labels, Matrix(rows));
  ASSERT_TRUE(m.ok()) << m.status();
  ASSERT_EQ(m->queries, 3u);
  ExpectScores(
      m->per_query[0].scores, 1, 0.5, 0.5, 1.0 / 17, (1 + 1 / std::log2(39.0)) / 2, 2.0 / 3, "q0");
}

TEST(RetrievalMetricsTest, RejectsBadInputNamingTheProblem) {
  auto error = [](const std::vector<std::string>& labels, const std::vector<float>& d) {
    const auto m = EvaluateRetrieval(labels, d);
    EXPECT_EQ(m.status().code(), absl::StatusCode::kInvalidArgument);
    return std::string(m.status().message());
  };
  EXPECT_THAT(error({}, {}), HasSubstr("no models"));
  EXPECT_THAT(error(kSixLabels, std::vector<float>(35, 1.0f)),
              HasSubstr("got 35 distances for 6 labels (expected 6 x 6)"));
  std::vector<float> with_nan = kSixDistances;
  with_nan[1 * 6 + 2] = std::nanf("");
  EXPECT_THAT(error(kSixLabels, with_nan), HasSubstr("NaN at row 1, column 2"));
  std::vector<std::string> empty_label = kSixLabels;
  empty_label[4].clear();
  EXPECT_THAT(error(empty_label, kSixDistances), HasSubstr("model 4 has an empty class label"));
  EXPECT_THAT(error({"-1", "-1", "-1", "x", "x", "y"}, kSixDistances),
              HasSubstr("no model can be a query: each of the 3 classes of the 6 models"));
}

TEST(RetrievalMetricsTest, ThreadCountDoesNotChangeTheResult) {
  std::vector<std::string> labels;
  std::vector<float> distances;
  uint32_t state = 7;
  for (int i = 0; i < 60; ++i) labels.push_back(std::string(1, static_cast<char>('a' + i % 5)));
  for (int i = 0; i < 60 * 60; ++i) {
    state = state * 1664525u + 1013904223u;
    distances.push_back(static_cast<float>(state >> 28));  // 16 levels: many ties
  }
  const auto one = EvaluateRetrieval(labels, distances, 1);
  const auto many = EvaluateRetrieval(labels, distances, 4);
  ASSERT_TRUE(one.ok() && many.ok());
  EXPECT_EQ(MetricsToJson(*one).Dump(0), MetricsToJson(*many).Dump(0));
}

// Reads `"<key>": <number>` inside the object that follows `"<section>"` in
// the JSON psb_eval.py writes (or at top level when section is empty).
double JsonNumber(const std::string& json, const std::string& section, const std::string& key) {
  std::size_t begin = 0, end = json.size();
  if (!section.empty()) {
    begin = json.find("\"" + section + "\"");
    EXPECT_NE(begin, std::string::npos) << section;
    end = json.find('}', begin);
  }
  const std::size_t at = json.find("\"" + key + "\":", begin);
  EXPECT_LT(at, end) << section << "." << key;
  if (at >= end) return std::nan("");
  return std::strtod(json.c_str() + at + key.size() + 3, nullptr);
}

// The fixture's matrix has many ties, one infinity, a misc class and a class of
// two, and its manifest interleaves the classes; expected_psb_eval.json is
// what tools/psb_eval.py (an independent implementation) says about it.
TEST(RetrievalMetricsTest, AgreesWithTheIndependentEvaluatorOnTheFixture) {
  const auto entries = ReadManifest(FixturePath("manifest.csv"));
  ASSERT_TRUE(entries.ok()) << entries.status();
  std::vector<std::string> labels;
  for (const ManifestEntry& e : *entries) labels.push_back(e.label);
  const auto distances = ReadDistanceMatrix(FixturePath("distances.bin"), labels.size());
  ASSERT_TRUE(distances.ok()) << distances.status();
  const auto m = EvaluateRetrieval(labels, *distances);
  ASSERT_TRUE(m.ok()) << m.status();

  const std::string json = ReadText(FixturePath("expected_psb_eval.json"));
  ASSERT_FALSE(json.empty());
  EXPECT_EQ(static_cast<double>(m->queries), JsonNumber(json, "", "queries"));
  EXPECT_EQ(static_cast<double>(m->classes), JsonNumber(json, "", "classes"));
  for (const auto& [section, scores] : {std::make_pair(std::string("micro"), m->micro),
                                        std::make_pair(std::string("macro"), m->macro)}) {
    const std::pair<const char*, double> values[] = {
        {"NN", scores.nn},
        {"FT", scores.first_tier},
        {"ST", scores.second_tier},
        {"E", scores.e_measure},
        {"DCG", scores.dcg},
        {"RP_excl", scores.rp_excl},
        {"RP_incl", scores.rp_incl},
    };
    for (const auto& [key, value] : values) {
      EXPECT_NEAR(100 * value, JsonNumber(json, section, key), 1e-9) << section << "." << key;
    }
  }
  // The printed table matches psb_eval.py's, character for character.
  EXPECT_EQ(FormatMetricsTable(*m), ReadText(FixturePath("expected_psb_eval.txt")));
}

TEST(RetrievalMetricsTest, TableAndJsonReportPercent) {
  const auto m = EvaluateRetrieval(kSixLabels, kSixDistances);
  ASSERT_TRUE(m.ok()) << m.status();
  EXPECT_EQ(FormatMetricsTable(*m),
            "6 queries in 2 classes (percent)\n"
            "              NN       FT       ST        E      DCG  RP_excl  RP_incl\n"
            "  micro     50.0     41.7     83.3     57.1     71.9     41.7     61.1\n"
            "  macro     50.0     41.7     83.3     57.1     71.9     41.7     61.1\n");
  const std::string json = MetricsToJson(*m).Dump(0);
  EXPECT_THAT(json, HasSubstr(R"({"queries":6,"classes":2,"micro":{"NN":50,"FT":41.6)"));
  EXPECT_THAT(json, HasSubstr(R"("ST":83.3)"));
  EXPECT_THAT(json, HasSubstr(R"("macro":{"NN":50,)"));
  EXPECT_THAT(json, HasSubstr(R"("per_class":{"A":{"NN":33.3)"));
  EXPECT_THAT(json, HasSubstr(R"(,"B":{"NN":66.6)"));
  EXPECT_NEAR(JsonNumber(json, "macro", "RP_incl"), 100 * 11.0 / 18, 1e-9);
}

}  // namespace
}  // namespace meshseek
