#include "common/eval/retrieval_metrics.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iterator>
#include <limits>
#include <unordered_map>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "common/base/parallel.h"
#include "common/base/status_macros.h"
#include "common/eval/class_file.h"

namespace meshseek {
namespace {

// Field order of the reports, and the keys psb_eval.py uses for them.
constexpr ScoreColumn kColumns[] = {
    {"NN", &RetrievalScores::nn},
    {"FT", &RetrievalScores::first_tier},
    {"ST", &RetrievalScores::second_tier},
    {"E", &RetrievalScores::e_measure},
    {"DCG", &RetrievalScores::dcg},
    {"RP_excl", &RetrievalScores::rp_excl},
    {"RP_incl", &RetrievalScores::rp_incl},
};

void Accumulate(const RetrievalScores& s, RetrievalScores* sum) {
  for (const auto& col : kColumns) sum->*col.field += s.*col.field;
}

RetrievalScores Divide(RetrievalScores sum, double count) {
  for (const auto& col : kColumns) sum.*col.field /= count;
  return sum;
}

Json ScoresToJson(const RetrievalScores& s) {
  Json j = Json::MakeObject();
  for (const auto& col : kColumns) j.Set(col.key, 100.0 * (s.*col.field));
  return j;
}

// Scores of query q, whose class (index label_id[q]) has class_size models.
// `discount[r]` is the DCG gain of a hit at 0-based rank r.
RetrievalScores ScoreQuery(std::size_t q,
                           std::size_t class_size,
                           const std::vector<int>& label_id,
                           const std::vector<float>& distances,
                           const std::vector<double>& discount) {
  const std::size_t n = label_id.size();
  const std::vector<std::pair<float, uint32_t>> ranking = RankOthers(distances, n, q);

  const std::size_t k = class_size - 1;
  const std::size_t top = std::min<std::size_t>(32, n - 1);
  const int c = label_id[q];
  std::size_t hits_k = 0, hits_2k = 0, hits_top = 0;
  double dcg = 0;
  for (std::size_t r = 0; r < ranking.size(); ++r) {
    if (label_id[ranking[r].second] != c) continue;
    hits_k += r < k;
    hits_2k += r < 2 * k;
    hits_top += r < top;
    dcg += discount[r];
  }
  double ideal = 0;
  for (std::size_t r = 1; r < k; ++r) ideal += discount[r];
  ideal += 1;  // rank 1, added last as psb_eval.py does

  RetrievalScores s;
  s.nn = label_id[ranking[0].second] == c ? 1 : 0;
  s.first_tier = static_cast<double>(hits_k) / k;
  s.second_tier = static_cast<double>(hits_2k) / k;
  s.e_measure = 2.0 * hits_top / (top + k);  // = 2PR / (P + R), P = h/top, R = h/k
  s.dcg = dcg / ideal;
  s.rp_excl = s.first_tier;
  s.rp_incl = static_cast<double>(1 + hits_k) / (k + 1);
  return s;
}

}  // namespace

absl::Span<const ScoreColumn> ScoreColumns() { return kColumns; }

std::vector<std::pair<float, uint32_t>> RankOthers(const std::vector<float>& distances,
                                                   std::size_t n,
                                                   std::size_t q,
                                                   std::size_t top) {
  const float* row = distances.data() + q * n;
  // Sorting (distance, index) pairs gives psb_eval.py's tie rule for free
  // and keeps the comparisons on contiguous memory.
  std::vector<std::pair<float, uint32_t>> ranking;
  ranking.reserve(n - 1);
  for (std::size_t j = 0; j < n; ++j) {
    if (j != q) ranking.emplace_back(row[j], static_cast<uint32_t>(j));
  }
  top = std::min(top, ranking.size());
  std::partial_sort(ranking.begin(), ranking.begin() + top, ranking.end());
  ranking.resize(top);
  return ranking;
}

absl::StatusOr<QueryClasses> ClassifyQueries(const std::vector<std::string>& labels,
                                             const std::vector<float>& distances) {
  const std::size_t n = labels.size();
  if (n == 0) return absl::InvalidArgumentError("no models to evaluate (empty label list)");
  if (n > std::numeric_limits<uint32_t>::max() || distances.size() / n != n ||
      distances.size() % n != 0) {
    return absl::InvalidArgumentError(absl::StrCat(
        "got ", distances.size(), " distances for ", n, " labels (expected ", n, " x ", n, ")"));
  }
  for (std::size_t i = 0; i < distances.size(); ++i) {
    if (std::isnan(distances[i])) {
      return absl::InvalidArgumentError(
          absl::StrCat("distance matrix has NaN at row ", i / n, ", column ", i % n));
    }
  }

  // Integer class ids, so that evaluators compare ints rather than strings.
  QueryClasses classes;
  std::unordered_map<std::string, int> id_of_label;
  std::vector<std::string>& names = classes.names;
  std::vector<std::size_t>& size_of = classes.sizes;
  std::vector<int>& label_id = classes.class_of;
  label_id.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    if (labels[i].empty()) {
      return absl::InvalidArgumentError(absl::StrCat("model ", i, " has an empty class label"));
    }
    const auto [it, inserted] = id_of_label.emplace(labels[i], static_cast<int>(names.size()));
    if (inserted) {
      names.push_back(labels[i]);
      size_of.push_back(0);
    }
    label_id[i] = it->second;
    ++size_of[it->second];
  }

  std::vector<std::size_t>& queries = classes.queries;
  for (std::size_t i = 0; i < n; ++i) {
    if (labels[i] != kMiscClass && size_of[label_id[i]] > 2) queries.push_back(i);
  }
  if (queries.empty()) {
    return absl::InvalidArgumentError(absl::StrCat("no model can be a query: each of the ",
                                                   names.size(),
                                                   " classes of the ",
                                                   n,
                                                   " models has at most 2 models or is misc ('",
                                                   kMiscClass,
                                                   "')"));
  }

  return classes;
}

absl::StatusOr<RetrievalMetrics> EvaluateRetrieval(const std::vector<std::string>& labels,
                                                   const std::vector<float>& distances,
                                                   int num_threads) {
  MESHSEEK_ASSIGN_OR_RETURN(const QueryClasses classes, ClassifyQueries(labels, distances));
  const std::size_t n = labels.size();
  const std::vector<std::string>& names = classes.names;
  const std::vector<std::size_t>& size_of = classes.sizes;
  const std::vector<int>& label_id = classes.class_of;
  const std::vector<std::size_t>& queries = classes.queries;

  std::vector<double> discount(n);
  for (std::size_t r = 0; r < n; ++r) discount[r] = r == 0 ? 1.0 : 1.0 / std::log2(r + 1.0);

  RetrievalMetrics metrics;
  metrics.per_query.resize(queries.size());
  ParallelFor(queries.size(), num_threads, [&](std::size_t i) {
    const std::size_t q = queries[i];
    metrics.per_query[i] = {q, ScoreQuery(q, size_of[label_id[q]], label_id, distances, discount)};
  });

  // Sums in query order, as psb_eval.py does, so that the averages agree to
  // the last bits.
  std::vector<RetrievalScores> class_sum(names.size());
  std::vector<int> class_slot(names.size(), -1);  // index into per_class
  std::vector<std::size_t> class_queries;
  RetrievalScores micro_sum;
  for (const QueryScores& qs : metrics.per_query) {
    const int c = label_id[qs.model];
    if (class_slot[c] < 0) {
      class_slot[c] = static_cast<int>(metrics.per_class.size());
      metrics.per_class.emplace_back(names[c], RetrievalScores{});
      class_queries.push_back(0);
    }
    Accumulate(qs.scores, &micro_sum);
    Accumulate(qs.scores, &metrics.per_class[class_slot[c]].second);
    ++class_queries[class_slot[c]];
  }
  RetrievalScores macro_sum;
  for (std::size_t s = 0; s < metrics.per_class.size(); ++s) {
    RetrievalScores& mean = metrics.per_class[s].second;
    mean = Divide(mean, static_cast<double>(class_queries[s]));
    Accumulate(mean, &macro_sum);
  }
  metrics.queries = metrics.per_query.size();
  metrics.classes = metrics.per_class.size();
  metrics.micro = Divide(micro_sum, static_cast<double>(metrics.queries));
  metrics.macro = Divide(macro_sum, static_cast<double>(metrics.classes));
  return metrics;
}

std::string FormatMetricsTable(const RetrievalMetrics& metrics) {
  std::string out =
      absl::StrCat(metrics.queries, " queries in ", metrics.classes, " classes (percent)\n");
  out.append(8, ' ');
  for (std::size_t c = 0; c < std::size(kColumns); ++c) {
    // The format must be a literal for clang's compile-time format check.
    if (c > 0) out.push_back(' ');
    absl::StrAppendFormat(&out, "%8s", kColumns[c].key);
  }
  out.push_back('\n');
  auto append_row = [&out](const char* name, const RetrievalScores& scores) {
    absl::StrAppendFormat(&out, "%7s ", name);
    for (std::size_t c = 0; c < std::size(kColumns); ++c) {
      if (c > 0) out.push_back(' ');
      absl::StrAppendFormat(&out, "%8.1f", 100.0 * (scores.*kColumns[c].field));
    }
    out.push_back('\n');
  };
  append_row("micro", metrics.micro);
  append_row("macro", metrics.macro);
  return out;
}

Json MetricsToJson(const RetrievalMetrics& metrics) {
  Json root = Json::MakeObject();
  root.Set("queries", metrics.queries);
  root.Set("classes", metrics.classes);
  root.Set("micro", ScoresToJson(metrics.micro));
  root.Set("macro", ScoresToJson(metrics.macro));
  Json& per_class = root.Set("per_class", Json::MakeObject());
  for (const auto& [name, scores] : metrics.per_class) per_class.Set(name, ScoresToJson(scores));
  return root;
}

}  // namespace meshseek
