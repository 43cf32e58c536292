// Load generator: the embedded stack (every service in this process on
// loopback, exactly what `meshseek serve` runs) under N concurrent clients.
//
//   load_benchmark [--query_clients 64] [--ingest_clients 4] [--duration 60s]
//                  [--models_per_class 8] [pipeline flags, e.g. --method dld]
//
// 1. writes the synthetic benchmark (`meshseek synth`) under --data_dir,
//    ingests it through the coordinator and builds its codebook and index;
// 2. for --duration, each query client sends Query calls back to back, its
//    mesh alternating between packed arrays (Mesh) and file bytes (MeshFile),
//    and each ingest client sends one new model per Ingest stream to a second
//    collection (the ack: validated and stored, extraction follows);
// 3. prints, per call kind, calls, throughput, latency p50 / p99 / max and
//    errors by status code. Exits 1 if any call failed.
// Every client has its own channel (its own connection), as separate
// processes would; calls are not retried, so every refusal is counted.
#include <algorithm>
#include <atomic>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <opencv2/core.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "absl/flags/flag.h"
#include "absl/flags/parse.h"
#include "absl/flags/usage.h"
#include "absl/strings/str_cat.h"
#include "absl/synchronization/mutex.h"
#include "absl/time/clock.h"
#include "services/embedded/embedded_stack.h"
#include "common/flags/pipeline_flags.h"
#include "common/base/status_macros.h"
#include "common/eval/manifest.h"
#include "common/geometry/mesh_io.h"
#include "common/rpc/client.h"
#include "common/wire/convert.h"
#include "common/rpc/status.h"
#include "common/synth/synthetic_benchmark.h"
#include "meshseek/v1/coordinator.grpc.pb.h"

ABSL_FLAG(int, query_clients, 64, "concurrent Query clients");
ABSL_FLAG(int, ingest_clients, 4, "concurrent Ingest clients (one model per stream)");
ABSL_FLAG(absl::Duration, duration, absl::Seconds(60), "how long the clients run");
ABSL_FLAG(int, models_per_class, 8, "synthetic models per class (the collection queried)");
ABSL_FLAG(std::string, data_dir, "", "state folder (default: a fresh temporary one, removed)");
ABSL_FLAG(absl::Duration, call_deadline, absl::Minutes(5), "deadline of every call");

namespace meshseek {
namespace {

// Latencies and failures of one call kind, over all its clients.
class Tally {
 public:
  void Add(absl::Duration latency, const grpc::Status& status) {
    absl::MutexLock lock(&mutex_);
    if (status.ok()) {
      latencies_ms_.push_back(absl::ToDoubleMilliseconds(latency));
    } else {
      ++errors_[status.error_code()];
      if (first_error_.empty()) first_error_ = status.error_message();
    }
  }
  // One line: kind, calls, calls/s, p50, p99, max, errors. Returns the errors.
  int Print(const char* kind, absl::Duration elapsed) {
    absl::MutexLock lock(&mutex_);
    std::sort(latencies_ms_.begin(), latencies_ms_.end());
    auto quantile = [&](double q) {
      if (latencies_ms_.empty()) return 0.0;
      return latencies_ms_[std::min(latencies_ms_.size() - 1,
                                    static_cast<std::size_t>(q * latencies_ms_.size()))];
    };
    int errors = 0;
    std::string codes;
    for (const auto& [code, count] : errors_) {
      errors += count;
      absl::StrAppend(&codes, codes.empty() ? "" : ", ", count, " x code ", static_cast<int>(code));
    }
    const std::size_t calls = latencies_ms_.size() + errors;
    std::printf("%-7s %7zu calls %8.2f/s   p50 %8.1f ms   p99 %8.1f ms   max %8.1f ms   errors %d%s%s\n",
                kind, calls, calls / absl::ToDoubleSeconds(elapsed), quantile(0.5), quantile(0.99),
                latencies_ms_.empty() ? 0.0 : latencies_ms_.back(), errors,
                codes.empty() ? "" : absl::StrCat(" (", codes, "; first: ", first_error_, ")").c_str(),
                "");
    return errors;
  }

 private:
  absl::Mutex mutex_;
  std::vector<double> latencies_ms_ ABSL_GUARDED_BY(mutex_);
  std::map<grpc::StatusCode, int> errors_ ABSL_GUARDED_BY(mutex_);
  std::string first_error_ ABSL_GUARDED_BY(mutex_);
};

struct Model {
  ManifestEntry entry;
  v1::MeshInput arrays;  // Mesh
  v1::MeshInput file;    // MeshFile: the bytes as written by synth
};

absl::StatusOr<std::vector<Model>> LoadModels(const std::string& bench_dir) {
  MESHSEEK_ASSIGN_OR_RETURN(const std::vector<ManifestEntry> entries,
                            ReadManifest(bench_dir + "/manifest.csv"));
  std::vector<Model> models;
  for (const ManifestEntry& e : entries) {
    Model m;
    m.entry = e;
    MESHSEEK_ASSIGN_OR_RETURN(const TriangleMesh mesh, ReadMesh(e.path));
    wire::MeshToProto(mesh, m.arrays.mutable_mesh());
    std::ifstream in(e.path, std::ios::binary);
    std::ostringstream bytes;
    bytes << in.rdbuf();
    m.file.mutable_file()->set_data(bytes.str());
    m.file.mutable_file()->set_name(std::filesystem::path(e.path).filename().string());
    models.push_back(std::move(m));
  }
  return models;
}

// A client with a connection of its own, as a separate process would have.
std::unique_ptr<v1::Coordinator::Stub> Connect(const std::string& address) {
  rpc::ChannelOptions options;
  options.retry_service = "";
  options.own_connection = true;
  return v1::Coordinator::NewStub(rpc::MakeChannel(address, options));
}

grpc::Status IngestOne(v1::Coordinator::Stub* stub, const std::string& collection,
                       const std::string& id, const Model& model, absl::Duration deadline) {
  grpc::ClientContext context;
  rpc::SetDeadline(&context, deadline);
  auto stream = stub->Ingest(&context);
  v1::IngestRequest request;
  request.set_collection(collection);
  request.set_model_id(id);
  request.set_label(model.entry.label);
  *request.mutable_mesh() = model.arrays;
  stream->Write(request);
  stream->WritesDone();
  v1::IngestAck ack;
  const bool acked = stream->Read(&ack);
  grpc::Status status = stream->Finish();
  if (status.ok() && !acked) return grpc::Status(grpc::StatusCode::INTERNAL, "no ack");
  return status;
}

absl::Status CreateCollection(v1::Coordinator::Stub* stub,
                              const std::string& name,
                              const flags::ParamFlags& params) {
  grpc::ClientContext context;
  rpc::SetDeadline(&context, absl::Minutes(1));
  v1::CreateCollectionRequest request;
  request.set_name(name);
  MESHSEEK_ASSIGN_OR_RETURN(*request.mutable_params(), flags::CollectionParamsFromFlags(params));
  v1::Collection response;
  return rpc::FromGrpcStatus(stub->CreateCollection(&context, request, &response));
}

absl::Status WaitFor(v1::Coordinator::Stub* stub, const std::string& job_id) {
  while (true) {
    grpc::ClientContext context;
    rpc::SetDeadline(&context, absl::Minutes(1));
    v1::JobRequest request;
    request.set_job_id(job_id);
    v1::JobStatus job;
    MESHSEEK_RETURN_IF_ERROR(rpc::FromGrpcStatus(stub->GetJob(&context, request, &job)));
    if (job.state() == v1::JOB_STATE_SUCCEEDED) return absl::OkStatus();
    if (job.state() != v1::JOB_STATE_RUNNING) {
      return absl::InternalError(absl::StrCat(job_id, ": ", job.message()));
    }
    absl::SleepFor(absl::Milliseconds(200));
  }
}

// Set-up: the queried collection "load" ingested and built, and an empty
// "load-ingest" for the ingest clients.
absl::Status SetUp(v1::Coordinator::Stub* setup,
                   const std::vector<Model>& models,
                   const flags::ParamFlags& params) {
  const absl::Time start = absl::Now();
  const absl::Duration deadline = absl::GetFlag(FLAGS_call_deadline);
  MESHSEEK_RETURN_IF_ERROR(CreateCollection(setup, "load", params));
  MESHSEEK_RETURN_IF_ERROR(CreateCollection(setup, "load-ingest", params));
  for (const Model& m : models) {
    MESHSEEK_RETURN_IF_ERROR(
        rpc::FromGrpcStatus(IngestOne(setup, "load", m.entry.id, m, deadline)));
  }
  for (uint64_t done = 0; done < models.size();) {
    absl::SleepFor(absl::Milliseconds(200));
    grpc::ClientContext context;
    rpc::SetDeadline(&context, absl::Minutes(1));
    v1::GetCollectionRequest request;
    request.set_name("load");
    v1::Collection info;
    MESHSEEK_RETURN_IF_ERROR(rpc::FromGrpcStatus(setup->GetCollection(&context, request, &info)));
    done = info.extracted();
  }
  grpc::ClientContext context;
  rpc::SetDeadline(&context, absl::Minutes(1));
  v1::BuildRequest request;
  request.set_collection("load");
  v1::JobStatus job;
  MESHSEEK_RETURN_IF_ERROR(rpc::FromGrpcStatus(setup->Build(&context, request, &job)));
  MESHSEEK_RETURN_IF_ERROR(WaitFor(setup, job.job_id()));
  std::printf("set-up: %zu synthetic models ingested and built in %.1f s\n", models.size(),
              absl::ToDoubleSeconds(absl::Now() - start));
  return absl::OkStatus();
}

// The load: query and ingest clients for --duration; the calls failed.
int Load(const std::string& address, const std::vector<Model>& models) {
  const absl::Duration deadline = absl::GetFlag(FLAGS_call_deadline);
  const int query_clients = absl::GetFlag(FLAGS_query_clients);
  const int ingest_clients = absl::GetFlag(FLAGS_ingest_clients);
  Tally query_mesh, query_file, ingest;
  std::atomic<bool> stop{false};
  std::vector<std::thread> clients;
  const absl::Time start = absl::Now();
  for (int c = 0; c < query_clients; ++c) {
    clients.emplace_back([&, c] {
      auto stub = Connect(address);
      for (std::size_t i = c; !stop.load(); i += query_clients) {
        const Model& m = models[i % models.size()];
        const bool as_file = (i / query_clients) % 2 == 1;
        v1::QueryRequest request;
        request.set_collection("load");
        request.set_top_k(10);
        *request.mutable_mesh() = as_file ? m.file : m.arrays;
        v1::QueryResponse response;
        grpc::ClientContext context;
        rpc::SetDeadline(&context, deadline);
        const absl::Time t = absl::Now();
        const grpc::Status status = stub->Query(&context, request, &response);
        (as_file ? query_file : query_mesh).Add(absl::Now() - t, status);
      }
    });
  }
  for (int c = 0; c < ingest_clients; ++c) {
    clients.emplace_back([&, c] {
      auto stub = Connect(address);
      for (int n = 0; !stop.load(); ++n) {
        const Model& m = models[(c + n * ingest_clients) % models.size()];
        const absl::Time t = absl::Now();
        const grpc::Status status =
            IngestOne(stub.get(), "load-ingest", absl::StrCat("c", c, "-", n), m, deadline);
        ingest.Add(absl::Now() - t, status);
      }
    });
  }
  absl::SleepFor(absl::GetFlag(FLAGS_duration));
  stop = true;
  for (auto& t : clients) t.join();  // calls in flight finish and count
  const absl::Duration elapsed = absl::Now() - start;
  std::printf("load: %d query clients, %d ingest clients, %.1f s (clients stop after --duration "
              "and finish their call in flight)\n",
              query_clients, ingest_clients, absl::ToDoubleSeconds(elapsed));
  int errors = query_mesh.Print("query", elapsed);
  errors += query_file.Print("query-f", elapsed);
  errors += ingest.Print("ingest", elapsed);
  std::printf("(query: mesh as arrays; query-f: as MeshFile bytes; ingest: ack of one model per "
              "stream)\n");
  return errors;
}

absl::Status Run(const flags::ParamFlags& params) {
  std::string data_dir = absl::GetFlag(FLAGS_data_dir);
  const bool temporary = data_dir.empty();
  if (temporary) {
    data_dir = (std::filesystem::temp_directory_path() /
                absl::StrCat("meshseek-load-", getpid())).string();
  }
  SyntheticBenchmarkOptions synth;
  synth.models_per_class = absl::GetFlag(FLAGS_models_per_class);
  MESHSEEK_RETURN_IF_ERROR(GenerateSyntheticBenchmark(synth, data_dir + "/bench"));
  MESHSEEK_ASSIGN_OR_RETURN(const std::vector<Model> models, LoadModels(data_dir + "/bench"));
  MESHSEEK_ASSIGN_OR_RETURN(auto stack,
                            EmbeddedStack::Start(data_dir + "/stack", params.threads));
  MESHSEEK_RETURN_IF_ERROR(SetUp(Connect(stack->coordinator_address()).get(), models, params));
  const int errors = Load(stack->coordinator_address(), models);
  stack.reset();
  if (temporary) std::filesystem::remove_all(data_dir);
  if (errors > 0) return absl::InternalError(absl::StrCat(errors, " calls failed"));
  return absl::OkStatus();
}

}  // namespace
}  // namespace meshseek

int main(int argc, char** argv) {
  const meshseek::flags::CommandLine line = meshseek::flags::ParseCommandLineWithParams(
      argc, argv, "load generator: N concurrent Query and Ingest clients on the embedded stack");
  cv::setNumThreads(0);  // meshseek parallelises across calls itself, as the CLI does
  const absl::Status status = meshseek::Run(line.params);
  if (!status.ok()) {
    std::fprintf(stderr, "load_benchmark: %s\n", std::string(status.message()).c_str());
    return 1;
  }
  return 0;
}
