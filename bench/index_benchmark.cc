// Index service benchmark through gRPC: a real meshseek-index process on a
// loopback port, filled with synthetic histograms shaped like real ones,
// then searched. For each collection size it reports the add rate, the
// server's resident memory (VmRSS, and the engine's own count), Search
// latency p50/p95/p99 for top-k from one client and throughput from several,
// and the restart (load) time.
//
// Synthetic histograms (synthetic_histograms.h): about 920 distinct words at
// V = 2,000, 1,600 at V = 20,000. Queries are fresh histograms of the same
// kind.
//
//   build/bench/index_benchmark --sizes=1000,10000,100000 --vocabulary=2000
#include <fcntl.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <netinet/in.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "absl/flags/flag.h"
#include "absl/flags/parse.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_split.h"
#include "common/search/synthetic_histograms.h"
#include "common/rpc/client.h"
#include "common/rpc/free_port.h"
#include "common/wire/convert.h"
#include "grpc/health/v1/health.grpc.pb.h"
#include "meshseek/v1/index.grpc.pb.h"

ABSL_FLAG(std::string, sizes, "1000,10000,100000", "collection sizes, comma-separated");
ABSL_FLAG(int, vocabulary, 2000, "vocabulary size V");
ABSL_FLAG(int, descriptors, 3000, "local features per synthetic model");
ABSL_FLAG(int, queries, 200, "queries per size (one client)");
ABSL_FLAG(int, top_k, 10, "results per query");
ABSL_FLAG(std::string, candidates, "1000,2000,5000",
          "candidate counts to measure beside exact search (comma-separated)");
ABSL_FLAG(int, clients, 4, "concurrent clients for the add phase and the throughput phase");
ABSL_FLAG(int, server_threads, 0, "--threads of the index server (0: all cores)");
ABSL_FLAG(std::string, index_binary, "build/services/meshseek-index", "the index server");
ABSL_FLAG(std::string, data_dir, "/tmp/meshseek-index-bench", "state folder (wiped per size)");

namespace meshseek {
namespace {

using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point since) {
  return std::chrono::duration<double>(Clock::now() - since).count();
}


// The index server as a child process.
class IndexProcess {
 public:
  IndexProcess(const std::string& data_dir, int port) : data_dir_(data_dir), port_(port) {}
  ~IndexProcess() { Stop(); }
  bool Start() {
    pid_ = fork();
    if (pid_ == 0) {
      const int fd = ::open((data_dir_ + ".log").c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
      dup2(fd, 1);
      dup2(fd, 2);
      const std::string binary = absl::GetFlag(FLAGS_index_binary);
      std::vector<std::string> args = {binary, absl::StrCat("--port=", port_),
                                       "--data_dir=" + data_dir_,
                                       absl::StrCat("--threads=", absl::GetFlag(FLAGS_server_threads)),
                                       "--server_threads=64"};
      std::vector<char*> argv;
      for (auto& a : args) argv.push_back(a.data());
      argv.push_back(nullptr);
      execv(argv[0], argv.data());
      _exit(127);
    }
    for (int i = 0; i < 30000; ++i) {
      // A fresh channel each time: a channel's reconnect backoff would add
      // seconds to the measured start.
      auto health = grpc::health::v1::Health::NewStub(
          grpc::CreateChannel(Address(), grpc::InsecureChannelCredentials()));
      grpc::ClientContext context;
      rpc::SetDeadline(&context, absl::Milliseconds(500));
      grpc::health::v1::HealthCheckRequest request;
      grpc::health::v1::HealthCheckResponse response;
      if (health->Check(&context, request, &response).ok() &&
          response.status() == grpc::health::v1::HealthCheckResponse::SERVING) {
        return true;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return false;
  }
  void Stop() {
    if (pid_ <= 0) return;
    ::kill(pid_, SIGKILL);
    waitpid(pid_, nullptr, 0);
    pid_ = -1;
  }
  // Resident memory of the server in MiB.
  double RssMiB() const {
    std::ifstream status(absl::StrCat("/proc/", pid_, "/status"));
    std::string line;
    while (std::getline(status, line)) {
      if (line.rfind("VmRSS:", 0) == 0) return std::atof(line.c_str() + 6) / 1024.0;
    }
    return -1;
  }
  std::string Address() const { return absl::StrCat("127.0.0.1:", port_); }

 private:
  std::string data_dir_;
  int port_;
  pid_t pid_ = -1;
};

// A synthetic histogram (see the file comment), normalised counts.
void MakeHistogram(std::mt19937_64& rng, int vocabulary, int descriptors,
                   v1::SparseHistogram* out) {
  wire::SparseHistogramToProto(SyntheticHistogram(rng, vocabulary, descriptors), out);
}

double Percentile(std::vector<double> values, double p) {
  std::sort(values.begin(), values.end());
  return values[std::min(values.size() - 1, static_cast<std::size_t>(p * values.size()))];
}

void RunSize(std::size_t n) {
  const int vocabulary = absl::GetFlag(FLAGS_vocabulary);
  const int descriptors = absl::GetFlag(FLAGS_descriptors);
  const int clients = absl::GetFlag(FLAGS_clients);
  const std::string dir = absl::StrCat(absl::GetFlag(FLAGS_data_dir), "/n", n);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  IndexProcess server(dir, rpc::FreeLoopbackPort());
  if (!server.Start()) {
    std::fprintf(stderr, "index server did not start (see %s.log)\n", dir.c_str());
    std::exit(1);
  }
  auto channel = rpc::MakeChannel(server.Address());
  const std::string collection = "bench";

  // Adds from `clients` threads, each model once.
  std::atomic<std::size_t> next{0}, failed{0}, words{0};
  const auto add_start = Clock::now();
  std::vector<std::thread> threads;
  for (int c = 0; c < clients; ++c) {
    threads.emplace_back([&, c] {
      auto stub = v1::Index::NewStub(channel);
      std::mt19937_64 rng(1000 + c);
      v1::AddModelRequest request;
      request.set_collection(collection);
      for (std::size_t i = next++; i < n; i = next++) {
        request.set_model_id(absl::StrCat("m", i));
        request.set_ordinal(i);
        MakeHistogram(rng, vocabulary, descriptors, request.mutable_histogram());
        words += request.histogram().bins_size();
        grpc::ClientContext context;
        rpc::SetDeadline(&context, absl::Seconds(60));
        v1::AddModelResponse response;
        if (!stub->AddModel(&context, request, &response).ok()) ++failed;
      }
    });
  }
  for (auto& t : threads) t.join();
  threads.clear();
  const double add_seconds = Seconds(add_start);
  const double rss = server.RssMiB();

  // Latency: one client, sequential queries, exact and with each number of
  // candidates (the same queries); recall@k of the candidate modes against
  // the exact answers.
  auto stub = v1::Index::NewStub(channel);
  const int top_k = absl::GetFlag(FLAGS_top_k);
  std::vector<uint32_t> modes = {0};
  for (absl::string_view c : absl::StrSplit(absl::GetFlag(FLAGS_candidates), ',', absl::SkipEmpty())) {
    uint32_t value = 0;
    if (absl::SimpleAtoi(c, &value) && value > 0) modes.push_back(value);
  }
  std::vector<std::vector<std::string>> exact_ids;
  std::string latency_report;
  for (uint32_t candidates : modes) {
    std::mt19937_64 rng(7);
    v1::SearchRequest search;
    search.set_collection(collection);
    search.set_top_k(top_k);
    search.set_candidates(candidates);
    std::vector<double> latencies;
    std::size_t errors = 0, found = 0, wanted = 0;
    for (int q = 0; q < absl::GetFlag(FLAGS_queries); ++q) {
      MakeHistogram(rng, vocabulary, descriptors, search.mutable_histogram());
      grpc::ClientContext context;
      rpc::SetDeadline(&context, absl::Seconds(60));
      v1::SearchResponse response;
      const auto start = Clock::now();
      const grpc::Status status = stub->Search(&context, search, &response);
      latencies.push_back(Seconds(start) * 1e3);
      if (!status.ok() || response.results_size() != top_k) ++errors;
      std::vector<std::string> ids;
      for (const auto& r : response.results()) ids.push_back(r.model_id());
      if (candidates == 0) {
        exact_ids.push_back(ids);
      } else {
        for (const std::string& id : ids) {
          found += std::count(exact_ids[q].begin(), exact_ids[q].end(), id);
        }
        wanted += exact_ids[q].size();
      }
    }
    absl::StrAppendFormat(&latency_report,
                          "\n    %-16s p50 %7.2f ms  p95 %7.2f ms  p99 %7.2f ms  %s(%zu errors)",
                          candidates == 0 ? "exact" : absl::StrCat(candidates, " candidates"),
                          Percentile(latencies, 0.5), Percentile(latencies, 0.95),
                          Percentile(latencies, 0.99),
                          candidates == 0 ? std::string()
                                          : absl::StrFormat("recall@%d %.4f  ", top_k,
                                                            static_cast<double>(found) / wanted),
                          errors);
  }

  // Throughput: `clients` clients for the same number of queries each, in
  // the last mode.
  v1::SearchRequest search;
  search.set_collection(collection);
  search.set_top_k(top_k);
  search.set_candidates(modes.back());
  std::atomic<std::size_t> served{0};
  const auto throughput_start = Clock::now();
  for (int c = 0; c < clients; ++c) {
    threads.emplace_back([&, c] {
      auto client = v1::Index::NewStub(channel);
      std::mt19937_64 local(50 + c);
      v1::SearchRequest request = search;
      const int each = std::max(1, absl::GetFlag(FLAGS_queries) / clients);
      for (int q = 0; q < each; ++q) {
        MakeHistogram(local, vocabulary, descriptors, request.mutable_histogram());
        grpc::ClientContext context;
        rpc::SetDeadline(&context, absl::Seconds(120));
        v1::SearchResponse response;
        if (client->Search(&context, request, &response).ok()) ++served;
      }
    });
  }
  for (auto& t : threads) t.join();
  const double qps = served / Seconds(throughput_start);

  // Restart: the time until the index serves again (loaded from SQLite).
  server.Stop();
  const auto restart = Clock::now();
  server.Start();
  const double load_seconds = Seconds(restart);
  const double rss_after_load = server.RssMiB();

  std::printf(
      "V=%d models=%zu words/model=%.0f: add %.0f models/s (%zu failed), server RSS %.0f MiB "
      "(%.0f after restart), restart %.1f s, %.1f queries/s with %d clients (%s); search top-%d:%s\n",
      vocabulary, n, static_cast<double>(words) / n, n / add_seconds, failed.load(), rss,
      rss_after_load, load_seconds, qps, clients,
      modes.back() == 0 ? "exact" : absl::StrCat(modes.back(), " candidates").c_str(), top_k,
      latency_report.c_str());
  std::fflush(stdout);
  server.Stop();
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace meshseek

int main(int argc, char** argv) {
  absl::ParseCommandLine(argc, argv);
  for (absl::string_view size : absl::StrSplit(absl::GetFlag(FLAGS_sizes), ',')) {
    std::size_t n = 0;
    if (!absl::SimpleAtoi(size, &n) || n == 0) {
      std::fprintf(stderr, "bad size '%s'\n", std::string(size).c_str());
      return 2;
    }
    meshseek::RunSize(n);
  }
  return 0;
}
