// The default fusion at collection scale, on real index servers: synthetic
// member histograms shaped like the four methods' real ones (each method's
// vocabulary and its median local features a McGill model, from
// metrics.json), added to meshseek-index processes over gRPC; then the
// coordinator's own code (IndexShards, ComputeRankingState, Ranking,
// fused_candidates.h) in this process builds the ranking state and answers
// fused queries, timed:
//
//   fused_scale_benchmark --models 10000 [--shards 1] [--candidates 50]
//     [--graph_candidates 50] [--exact_graph_models 0] [--queries 100]
//     [--postings_max_models 20000] [--live_models 5] [--method bfdsift+rld+lsf+lfd]
//
// Prints the add time, the ranking-state build time (approximate graph above
// --exact_graph_models), the search part of fused queries (after
// extraction: new synthetic signatures) with and without candidates, p50 and
// p95, the time from a new model's add to a query that returns it (live
// ingest, joined from candidates), and the peak resident memory and bytes on
// disk a model of each index server, and this process's peak (the
// coordinator's share: ids, the state, a batch of lists).
// What it leaves out of the services: the coordinator's SQLite store and
// extraction (the extraction of a query is bench/extract_benchmark's).
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "absl/flags/flag.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "common/search/synthetic_histograms.h"
#include "common/flags/pipeline_flags.h"
#include "common/base/parallel.h"
#include "common/base/status_macros.h"
#include "common/global/lfd.h"
#include "common/wire/convert.h"
#include "common/rpc/free_port.h"
#include "services/coordinator/fused_candidates.h"
#include "services/coordinator/ranking.h"

ABSL_FLAG(int, models, 1000, "models in the collection");
ABSL_FLAG(int, shards, 1, "index servers");
ABSL_FLAG(uint32_t, candidates, 50, "query candidates per method");
ABSL_FLAG(uint32_t, graph_candidates, 50, "candidates per method of the approximate graph");
ABSL_FLAG(int64_t, exact_graph_models, 0, "all pairs up to this many models");
ABSL_FLAG(int, queries, 100, "fused queries timed with candidates");
ABSL_FLAG(int, exact_queries, 20,
          "of those, timed exact too (a whole row of every method: seconds past the postings)");
ABSL_FLAG(std::string, work_dir, "", "the index servers' data (default: a temporary folder)");
ABSL_FLAG(std::size_t, postings_max_models, 20000,
          "the index servers' --postings_max_models (postings freed past it)");
ABSL_FLAG(int, live_models, 5, "models ingested after the build, timed to searchable");

namespace meshseek {
namespace {

// Median local features a McGill model (bench/results/fused_candidates.txt's
// eval, metrics.json): the word counts the synthetic histograms draw.
int FeaturesPerModel(FeatureMethod method) {
  switch (method) {
    case FeatureMethod::kBfDsift: return 25212;
    case FeatureMethod::kRldSift: return 3791;
    case FeatureMethod::kLsf: return 2048;
    default: return 3000;
  }
}

double Seconds(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// Peak resident memory of a process, from /proc (VmHWM), in MB.
double PeakMb(pid_t pid) {
  std::ifstream status(absl::StrCat("/proc/", pid == 0 ? "self" : std::to_string(pid), "/status"));
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("VmHWM:", 0) == 0) return std::stod(line.substr(6)) / 1024.0;
  }
  return -1;
}

std::string Percentiles(std::vector<double> ms) {
  std::sort(ms.begin(), ms.end());
  const auto at = [&](double q) { return ms[std::min(ms.size() - 1, std::size_t(q * ms.size()))]; };
  return absl::StrCat("p50 ", at(0.5), " ms, p95 ", at(0.95), " ms");
}

// A member's synthetic signature.
IndexSignature Signature(std::mt19937_64& rng, const RetrievalPipelineOptions& method) {
  IndexSignature s;
  if (method.extractor.method == FeatureMethod::kLfd) {
    std::string bytes(kLfdDescriptorBytes, '\0');
    for (std::size_t i = 0; i < bytes.size(); ++i) {
      if (i % kLfdViewStride < kLfdCoefficientsPerView) bytes[i] = static_cast<char>(rng() % 64);
    }
    v1::GlobalDescriptor d;
    d.set_method("lfd");
    d.set_data(bytes);
    s.descriptor = d;
    return s;
  }
  wire::SparseHistogramToProto(
      SyntheticHistogram(rng, static_cast<int>(method.kmeans.num_centroids),
                         FeaturesPerModel(method.extractor.method)),
      &s.histogram);
  return s;
}

struct IndexServers {
  std::vector<pid_t> pids;
  std::vector<std::string> targets;
};

// --shards meshseek-index processes, each on a free port with its folder
// under `work`, its log in the folder.
IndexServers StartIndexServers(const std::string& work) {
  IndexServers servers;
  for (int s = 0; s < absl::GetFlag(FLAGS_shards); ++s) {
    const int port = rpc::FreeLoopbackPort();
    const std::string dir = absl::StrCat(work, "/index-", s);
    std::filesystem::create_directories(dir);
    const pid_t pid = fork();
    if (pid == 0) {
      const std::string log = dir + "/log";
      freopen(log.c_str(), "w", stderr);
      const std::string postings =
          absl::StrCat("--postings_max_models=", absl::GetFlag(FLAGS_postings_max_models));
      execl(MESHSEEK_INDEX_PATH, MESHSEEK_INDEX_PATH, absl::StrCat("--port=", port).c_str(),
            absl::StrCat("--data_dir=", dir).c_str(), postings.c_str(), static_cast<char*>(nullptr));
      _exit(127);
    }
    servers.pids.push_back(pid);
    servers.targets.push_back(absl::StrCat("127.0.0.1:", port));
  }
  return servers;
}

// Peak memory and disk of each server; then stops it.
void ReportAndStop(const IndexServers& servers, const std::string& work, int n) {
  for (std::size_t s = 0; s < servers.pids.size(); ++s) {
    uint64_t disk = 0;
    std::error_code ec;
    for (const auto& f : std::filesystem::recursive_directory_iterator(
             absl::StrCat(work, "/index-", s), ec)) {
      if (f.is_regular_file()) disk += f.file_size();
    }
    std::printf("index shard %zu: peak RSS %.0f MB, %.1f KB a model on disk\n", s,
                PeakMb(servers.pids[s]), disk / 1024.0 / n);
    kill(servers.pids[s], SIGTERM);
    waitpid(servers.pids[s], nullptr, 0);
  }
}

// The coordinator's view of the fused collection "scale": one part a member.
CollectionPlan ScalePlan(const CollectionOptions& options) {
  CollectionPlan plan;
  plan.name = "scale";
  plan.options = options;
  for (const RetrievalPipelineOptions& method : options.methods) {
    CollectionInfo part;
    part.name = MemberCollectionName(plan.name, method.extractor.method);
    part.options = method;
    plan.parts.push_back(part);
  }
  return plan;
}

// Model i's signatures (seeded by i), added to every part; kept when asked.
absl::Status AddModel(IndexShards* index,
                      const CollectionPlan& plan,
                      std::size_t i,
                      std::vector<IndexSignature>* kept) {
  std::mt19937_64 rng(i + 1);
  for (const CollectionInfo& part : plan.parts) {
    IndexSignature s = Signature(rng, part.options);
    v1::AddModelRequest add;
    add.set_collection(part.name);
    add.set_model_id(absl::StrCat("m", i));
    add.set_ordinal(i);
    add.set_label(absl::StrCat("c", i % 50));
    if (s.descriptor.has_value()) {
      *add.mutable_global_descriptor() = *s.descriptor;
    } else {
      *add.mutable_histogram() = s.histogram;
    }
    MESHSEEK_RETURN_IF_ERROR(index->Add(add));
    if (kept != nullptr) kept->push_back(std::move(s));
  }
  return absl::OkStatus();
}

std::vector<const IndexSignature*> Pointers(const std::vector<IndexSignature>& signatures) {
  std::vector<const IndexSignature*> out;
  for (const IndexSignature& s : signatures) out.push_back(&s);
  return out;
}

// Step 3: fused queries of new signatures, exact and with candidates.
absl::Status TimeQueries(IndexShards* index, const CollectionPlan& plan, const Ranking& ranking) {
  std::mt19937_64 rng(0xfeed);
  std::vector<std::vector<IndexSignature>> queries(absl::GetFlag(FLAGS_queries));
  for (auto& q : queries) {
    for (const CollectionInfo& part : plan.parts) q.push_back(Signature(rng, part.options));
  }
  for (const uint32_t candidates : {0u, absl::GetFlag(FLAGS_candidates)}) {
    std::vector<double> ms;
    const std::size_t asked =
        candidates == 0 ? std::min<std::size_t>(queries.size(), absl::GetFlag(FLAGS_exact_queries))
                        : queries.size();
    for (std::size_t k = 0; k < asked; ++k) {
      const std::vector<const IndexSignature*> signatures = Pointers(queries[k]);
      const auto t = std::chrono::steady_clock::now();
      auto distances = candidates == 0
                           ? PartDistances(index, plan, signatures)
                           : CandidatePartDistances(index, plan, signatures, candidates);
      MESHSEEK_RETURN_IF_ERROR(distances.status());
      MESHSEEK_RETURN_IF_ERROR(ranking.Query(*distances, plan.options, 10).status());
      ms.push_back(Seconds(t) * 1e3);
    }
    std::printf("fused query, search part, %s: %s\n",
                candidates == 0 ? "exact" : absl::StrCat(candidates, " candidates").c_str(),
                Percentiles(ms).c_str());
  }
  return absl::OkStatus();
}

// Step 4: a model added after the build (its extraction done), joined from
// candidates as the coordinator's live index does, until a query with its
// signatures returns it first.
absl::Status TimeLiveIngest(IndexShards* index,
                            const CollectionPlan& plan,
                            uint32_t graph_candidates,
                            int n,
                            Ranking* ranking) {
  std::vector<double> live_ms;
  for (int l = 0; l < absl::GetFlag(FLAGS_live_models); ++l) {
    const std::size_t i = static_cast<std::size_t>(n) + l;
    const auto t = std::chrono::steady_clock::now();
    std::vector<IndexSignature> own;
    MESHSEEK_RETURN_IF_ERROR(AddModel(index, plan, i, &own));
    const std::vector<const IndexSignature*> signatures = Pointers(own);
    MESHSEEK_ASSIGN_OR_RETURN(auto distances,
                              CandidatePartDistances(index, plan, signatures, graph_candidates));
    MESHSEEK_ASSIGN_OR_RETURN(auto join,
                              ranking->PlanJoin(absl::StrCat("m", i), i, "", distances));
    MESHSEEK_RETURN_IF_ERROR(ranking->Apply(join));
    MESHSEEK_ASSIGN_OR_RETURN(
        auto asked,
        CandidatePartDistances(index, plan, signatures, absl::GetFlag(FLAGS_candidates)));
    MESHSEEK_ASSIGN_OR_RETURN(auto found, ranking->Query(asked, plan.options, 10));
    if (found.empty() || found[0].model_id() != absl::StrCat("m", i)) {
      return absl::InternalError(absl::StrCat("live model m", i, " not returned first"));
    }
    live_ms.push_back(Seconds(t) * 1e3);
  }
  if (!live_ms.empty()) {
    std::printf("live ingest, added to every part until a query returns it: %s\n",
                Percentiles(live_ms).c_str());
  }
  return absl::OkStatus();
}

absl::Status Run(const CollectionOptions& options, const IndexServers& servers, int n) {
  const std::atomic<bool> stop{false};
  IndexShards index(servers.targets, rpc::ChannelOptions{}, absl::Minutes(10), rpc::RetryOptions{},
                    &stop);
  const CollectionPlan plan = ScalePlan(options);
  // 1. Adds, several in flight (the first waits for the servers to start).
  auto start = std::chrono::steady_clock::now();
  std::vector<absl::Status> errors(n);
  ParallelFor(static_cast<std::size_t>(n), 8,
              [&](std::size_t i) { errors[i] = AddModel(&index, plan, i, nullptr); });
  for (const absl::Status& e : errors) MESHSEEK_RETURN_IF_ERROR(e);
  std::printf("%d models, %s, %zu index shard(s): added in %.1f s\n", n,
              options.MethodName().c_str(), servers.targets.size(), Seconds(start));
  // 2. The ranking state.
  RankingGraphOptions graph;
  graph.exact_graph_models = static_cast<std::size_t>(absl::GetFlag(FLAGS_exact_graph_models));
  graph.graph_candidates = absl::GetFlag(FLAGS_graph_candidates);
  start = std::chrono::steady_clock::now();
  MESHSEEK_ASSIGN_OR_RETURN(RankingState state, ComputeRankingState(&index, plan, graph));
  std::printf("ranking state (%s graph, %u candidates a method): %.1f s, %zu bytes\n",
              static_cast<std::size_t>(n) > graph.exact_graph_models ? "approximate" : "exact",
              graph.graph_candidates, Seconds(start), state.Serialize().size());
  MESHSEEK_ASSIGN_OR_RETURN(Ranking ranking,
                            Ranking::Make("bench", std::move(state), plan.options));
  MESHSEEK_RETURN_IF_ERROR(TimeQueries(&index, plan, ranking));
  return TimeLiveIngest(&index, plan, graph.graph_candidates, n, &ranking);
}

int Run(const flags::ParamFlags& params) {
  absl::StatusOr<CollectionOptions> options = flags::CollectionOptionsFromFlags(params);
  if (!options.ok() || !options->rescaled()) {
    std::fprintf(stderr, "--method must name a fused or re-ranked collection\n");
    return 2;
  }
  const int n = absl::GetFlag(FLAGS_models);
  std::string work = absl::GetFlag(FLAGS_work_dir);
  if (work.empty()) {
    work = std::filesystem::temp_directory_path() / absl::StrCat("fused-scale-", getpid());
  }
  const IndexServers servers = StartIndexServers(work);
  const absl::Status run = Run(*options, servers, n);
  if (!run.ok()) std::fprintf(stderr, "fused_scale_benchmark: %s\n", run.ToString().c_str());
  ReportAndStop(servers, work, n);
  std::printf("this process (the coordinator's code): peak RSS %.0f MB\n", PeakMb(0));
  std::error_code ec;
  if (absl::GetFlag(FLAGS_work_dir).empty()) std::filesystem::remove_all(work, ec);
  return run.ok() ? 0 : 1;
}

}  // namespace
}  // namespace meshseek

int main(int argc, char** argv) {
  // A line at a time, so that a run cut off by its time limit keeps what it measured.
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  const meshseek::flags::CommandLine line =
      meshseek::flags::ParseCommandLineWithParams(argc, argv, "fused_scale_benchmark --models N");
  return meshseek::Run(line.params);
}
