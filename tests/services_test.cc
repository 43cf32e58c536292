// Integration and fault tests of the real server binaries on loopback ports:
// the services path gives exactly the in-process distance matrix; a kill -9
// of an extract worker, of the index and of the coordinator loses no
// acknowledged model; bad input gets the right status code and a message
// naming the problem, and the servers keep serving.
#include <signal.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/time/clock.h"
#include "common/base/test_env.h"
#include "common/eval/manifest.h"
#include "common/geometry/mesh_io.h"
#include "common/pipeline/collection_evaluation.h"
#include "common/pipeline/pipeline_params.h"
#include "common/rpc/client.h"
#include "common/wire/convert.h"
#include "common/rpc/status.h"
#include "common/store/sqlite_db.h"
#include "common/synth/synthetic_benchmark.h"
#include "gmock/gmock.h"
#include "grpc/health/v1/health.grpc.pb.h"
#include "gtest/gtest.h"
#include "tests/server_process.h"
#include "meshseek/v1/codebook.grpc.pb.h"
#include "meshseek/v1/coordinator.grpc.pb.h"
#include "meshseek/v1/extract.grpc.pb.h"
#include "meshseek/v1/index.grpc.pb.h"

namespace meshseek {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

// CPU seconds (user + system) a process has used, from /proc/PID/stat.
double CpuSeconds(pid_t pid) {
  std::ifstream stat(absl::StrCat("/proc/", pid, "/stat"));
  std::string text((std::istreambuf_iterator<char>(stat)), std::istreambuf_iterator<char>());
  // Fields after the command's closing parenthesis; utime and stime are the
  // 12th and 13th of them.
  std::istringstream rest(text.substr(text.rfind(')') + 2));
  std::string field;
  double ticks = 0;
  for (int i = 1; i <= 13 && rest >> field; ++i) {
    if (i >= 12) ticks += std::stod(field);
  }
  return ticks / static_cast<double>(sysconf(_SC_CLK_TCK));
}


std::string Address(int port) { return absl::StrCat("127.0.0.1:", port); }

// A service binary of this build, its log in the test's folder.
class Server : public ServerProcess {
 public:
  Server(const std::string& role, std::vector<std::string> flags)
      : ServerProcess(Argv(role, std::move(flags)), Log(role)) {}

 private:
  static std::vector<std::string> Argv(const std::string& role, std::vector<std::string> flags) {
    std::vector<std::string> argv = {std::string(MESHSEEK_SERVICES_DIR) + "/meshseek-" + role,
                                     "--grace_period=1s"};
    argv.insert(argv.end(), flags.begin(), flags.end());
    return argv;
  }
  static std::string Log(const std::string& role) {
    static int started = 0;
    return absl::StrCat(::testing::TempDir(), "/", role, "-", ++started, ".log");
  }
};

// The whole stack: resample, `extract_workers` extract workers, codebook,
// `index_shards` index servers and coordinator, state under `dir`. The
// coordinator starts in the first WaitServing, once the others have said
// their ports.
class Stack {
 public:
  Stack(const std::string& dir, int extract_workers, int max_pending = 512, int index_shards = 1,
        const std::vector<std::string>& coordinator_flags = {}) {
    resample_ = std::make_unique<Server>("resample", std::vector<std::string>{});
    for (int w = 0; w < extract_workers; ++w) {
      extract_.push_back(std::make_unique<Server>("extract", std::vector<std::string>{"--workers=1"}));
    }
    codebook_ = std::make_unique<Server>("codebook",
                                         std::vector<std::string>{"--data_dir=" + dir + "/codebook"});
    for (int s = 0; s < index_shards; ++s) {
      index_.push_back(std::make_unique<Server>(
          "index", std::vector<std::string>{absl::StrCat("--data_dir=", dir, "/index", s)}));
    }
    coordinator_flags_ = {"--data_dir=" + dir + "/coordinator",
                          absl::StrCat("--max_in_flight=", extract_workers),
                          absl::StrCat("--max_pending=", max_pending)};
    coordinator_flags_.insert(coordinator_flags_.end(), coordinator_flags.begin(),
                              coordinator_flags.end());
  }
  bool WaitServing() {
    std::vector<Server*> servers = {resample_.get(), codebook_.get()};
    for (auto& s : index_) servers.push_back(s.get());
    for (auto& s : extract_) servers.push_back(s.get());
    for (Server* s : servers) {
      if (!s->WaitServing()) return false;
    }
    if (coordinator_ == nullptr) {
      std::string targets, shards;
      for (auto& e : extract_) absl::StrAppend(&targets, targets.empty() ? "" : ",", Address(e->port()));
      for (auto& i : index_) absl::StrAppend(&shards, shards.empty() ? "" : ",", Address(i->port()));
      std::vector<std::string> flags = {"--resample=" + Address(resample_->port()),
                                        "--extract=ipv4:" + targets,
                                        "--codebook=" + Address(codebook_->port()),
                                        "--index=" + shards};
      flags.insert(flags.end(), coordinator_flags_.begin(), coordinator_flags_.end());
      coordinator_ = std::make_unique<Server>("coordinator", flags);
    }
    return coordinator_->WaitServing();
  }
  std::unique_ptr<v1::Coordinator::Stub> Coordinator() const {
    return v1::Coordinator::NewStub(rpc::MakeChannel(Address(coordinator_->port())));
  }
  Server& coordinator() { return *coordinator_; }
  Server& index(int shard = 0) { return *index_[shard]; }
  Server& extract(int i) { return *extract_[i]; }
  Server& codebook() { return *codebook_; }

 private:
  std::unique_ptr<Server> resample_, codebook_, coordinator_;
  std::vector<std::unique_ptr<Server>> extract_, index_;
  std::vector<std::string> coordinator_flags_;
};

// Small parameters: the test is about the system, not accuracy.
v1::PipelineParams TestParams() {
  v1::PipelineParams params;
  params.set_method(v1::FEATURE_METHOD_DLD);
  params.set_num_points(96);
  params.set_vocabulary(24);
  return params;
}

class ServicesTest : public ::testing::Test {
 protected:
  // CTest runs each case as a process of its own (in a temporary folder of
  // its own): the benchmark is made per case, the reference only by the
  // cases that compare with it.
  static void SetUpTestSuite() {
    dir_ = new std::string(::testing::TempDir() + "/meshseek_services");
    std::filesystem::remove_all(*dir_);
    // Under a sanitizer, 4 models a class (36) instead of 8: every kill still
    // lands mid-ingest or mid-build, and the matrices still compare bit for bit.
    SyntheticBenchmarkOptions benchmark;
    if (kSanitized) benchmark.models_per_class = 4;
    ASSERT_TRUE(GenerateSyntheticBenchmark(benchmark, *dir_ + "/bench").ok());
    auto models = ReadManifest(*dir_ + "/bench/manifest.csv");
    ASSERT_TRUE(models.ok());
    models_ = new std::vector<ManifestEntry>(*models);
  }
  static void TearDownTestSuite() {
    delete dir_;
    delete models_;
    delete reference_;
    reference_ = nullptr;
  }

  // The in-process matrix of TestParams() over every model.
  static const std::vector<float>& Reference() {
    if (reference_ == nullptr) {
      auto options = wire::PipelineOptionsFromParams(TestParams());
      EXPECT_TRUE(options.ok()) << options.status();
      auto reference = EvaluateCollection(*models_, CollectionOptions::Of(*options));
      EXPECT_TRUE(reference.ok()) << reference.status();
      reference_ = new std::vector<float>(reference.ok() ? reference->distances : std::vector<float>());
    }
    return *reference_;
  }

  static absl::Status CreateCollection(v1::Coordinator::Stub* stub,
                                       const std::string& name,
                                       const v1::PipelineParams& params = TestParams()) {
    grpc::ClientContext context;
    rpc::SetDeadline(&context, absl::Seconds(10));
    v1::CreateCollectionRequest request;
    request.set_name(name);
    *request.mutable_params() = params;
    v1::Collection response;
    return rpc::FromGrpcStatus(stub->CreateCollection(&context, request, &response));
  }

  // Streams models [begin, end) and returns how many were acknowledged;
  // `after_ack(n)` runs after the n-th acknowledgement.
  static std::size_t Ingest(v1::Coordinator::Stub* stub, const std::string& collection,
                            std::size_t begin, std::size_t end, std::set<std::string>* jobs,
                            const std::function<void(std::size_t)>& after_ack = nullptr) {
    grpc::ClientContext context;
    // A guard against a hang, not a speed check (ctest's 600 s is the other):
    // under ThreadSanitizer on a loaded 2-core machine the 72 models took
    // more than 3 minutes (scripts/sanitize.sh tsan).
    rpc::SetDeadline(&context, absl::Minutes(8));
    context.set_wait_for_ready(true);  // the coordinator may just have restarted
    auto stream = stub->Ingest(&context);
    std::size_t acked = 0;
    std::thread reader([&] {
      v1::IngestAck ack;
      while (stream->Read(&ack)) {
        jobs->insert(ack.job_id());
        ++acked;
        if (after_ack) after_ack(acked);
      }
    });
    for (std::size_t i = begin; i < end; ++i) {
      const ManifestEntry& m = (*models_)[i];
      v1::IngestRequest request;
      request.set_collection(collection);
      request.set_model_id(m.id);
      request.set_label(m.label);
      auto mesh = ReadMesh(m.path);
      wire::MeshToProto(*mesh, request.mutable_mesh()->mutable_mesh());
      if (!stream->Write(request)) break;
    }
    stream->WritesDone();
    reader.join();
    stream->Finish();
    return acked;
  }

  // Polls a job until it ends (the coordinator may be restarting meanwhile).
  static v1::JobStatus WaitJob(v1::Coordinator::Stub* stub, const std::string& job_id) {
    v1::JobStatus status;
    for (int i = 0; i < 1200; ++i) {
      grpc::ClientContext context;
      rpc::SetDeadline(&context, absl::Seconds(2));
      v1::JobRequest request;
      request.set_job_id(job_id);
      if (stub->GetJob(&context, request, &status).ok() &&
          status.state() != v1::JOB_STATE_RUNNING) {
        return status;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    return status;
  }

  static std::string Build(v1::Coordinator::Stub* stub, const std::string& collection) {
    grpc::ClientContext context;
    rpc::SetDeadline(&context, absl::Seconds(10));
    context.set_wait_for_ready(true);
    v1::BuildRequest request;
    request.set_collection(collection);
    v1::JobStatus job;
    const grpc::Status status = stub->Build(&context, request, &job);
    EXPECT_TRUE(status.ok()) << status.error_message();
    return job.job_id();
  }

  // The collection's matrix, reordered to manifest order.
  static std::vector<float> Evaluate(v1::Coordinator::Stub* stub,
                                     const std::string& collection,
                                     std::size_t models = 0) {
    grpc::ClientContext context;
    rpc::SetDeadline(&context, absl::Minutes(1));
    context.set_wait_for_ready(true);
    v1::EvaluateRequest request;
    request.set_collection(collection);
    auto reader = stub->Evaluate(&context, request);
    const std::size_t n = models == 0 ? models_->size() : models;
    std::map<std::string, std::size_t> position;
    for (std::size_t i = 0; i < n; ++i) position[(*models_)[i].id] = i;
    std::vector<v1::EvaluateRow> rows;
    v1::EvaluateRow row;
    while (reader->Read(&row)) rows.push_back(row);
    const grpc::Status status = reader->Finish();
    EXPECT_TRUE(status.ok()) << status.error_message();
    if (rows.size() != n) return {};
    std::vector<float> matrix(n * n);
    for (const auto& r : rows) {
      for (std::size_t c = 0; c < n; ++c) {
        matrix[position[r.model_id()] * n + position[rows[c].model_id()]] = r.distances(c);
      }
    }
    return matrix;
  }

  // Query with model i's mesh, top_k results; `deadline` for the whole call.
  // `wait_for_ready`: wait within it for the channel to connect instead of
  // failing at once while the channel is in reconnect backoff.
  static grpc::Status Query(v1::Coordinator::Stub* stub, const std::string& collection,
                            std::size_t i, uint32_t top_k, absl::Duration deadline,
                            v1::QueryResponse* response, bool wait_for_ready = false) {
    grpc::ClientContext context;
    rpc::SetDeadline(&context, deadline);
    context.set_wait_for_ready(wait_for_ready);
    v1::QueryRequest request;
    request.set_collection(collection);
    request.set_top_k(top_k);
    wire::MeshToProto(*ReadMesh((*models_)[i].path), request.mutable_mesh()->mutable_mesh());
    return stub->Query(&context, request, response);
  }

  // The top_k of row i of the reference matrix: (distance, manifest order).
  static std::vector<std::pair<std::string, float>> ReferenceTop(std::size_t i, std::size_t top_k) {
    const std::size_t n = models_->size();
    std::vector<std::size_t> order(n);
    for (std::size_t j = 0; j < n; ++j) order[j] = j;
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
      return Reference()[i * n + a] < Reference()[i * n + b];
    });
    std::vector<std::pair<std::string, float>> top;
    for (std::size_t r = 0; r < top_k; ++r) {
      top.emplace_back((*models_)[order[r]].id, Reference()[i * n + order[r]]);
    }
    return top;
  }
  static std::vector<std::pair<std::string, float>> Results(const v1::QueryResponse& response) {
    std::vector<std::pair<std::string, float>> out;
    for (const auto& r : response.results()) out.emplace_back(r.model_id(), r.distance());
    return out;
  }

  static std::string* dir_;
  static std::vector<ManifestEntry>* models_;
  static std::vector<float>* reference_;
};
std::string* ServicesTest::dir_ = nullptr;
std::vector<ManifestEntry>* ServicesTest::models_ = nullptr;
std::vector<float>* ServicesTest::reference_ = nullptr;

TEST_F(ServicesTest, KilledExtractWorkerLosesNothingAndResultEqualsInProcess) {
  Stack stack(*dir_ + "/kill-extract", 2, /*max_pending=*/8);
  ASSERT_TRUE(stack.WaitServing());
  auto stub = stack.Coordinator();
  ASSERT_EQ(CreateCollection(stub.get(), "synthetic"), absl::OkStatus());
  std::set<std::string> jobs;
  const std::size_t n = models_->size();
  const std::size_t acked = Ingest(stub.get(), "synthetic", 0, n, &jobs, [&](std::size_t a) {
    if (a == 12) stack.extract(0).Kill(SIGKILL);  // mid-ingest, work in flight
  });
  ASSERT_EQ(acked, n);
  ASSERT_EQ(jobs.size(), 1u);
  const v1::JobStatus ingest = WaitJob(stub.get(), *jobs.begin());
  EXPECT_EQ(ingest.state(), v1::JOB_STATE_SUCCEEDED) << ingest.DebugString();
  EXPECT_EQ(ingest.done(), n);
  const v1::JobStatus build = WaitJob(stub.get(), Build(stub.get(), "synthetic"));
  ASSERT_EQ(build.state(), v1::JOB_STATE_SUCCEEDED) << build.DebugString();

  // Every model indexed exactly once.
  auto index = v1::Index::NewStub(rpc::MakeChannel(Address(stack.index().port())));
  grpc::ClientContext context;
  v1::ListModelsRequest list;
  list.set_collection("synthetic");
  v1::ListModelsResponse listed;
  ASSERT_TRUE(index->ListModels(&context, list, &listed).ok());
  std::set<std::string> ids(listed.model_ids().begin(), listed.model_ids().end());
  EXPECT_EQ(listed.model_ids_size(), static_cast<int>(n));
  EXPECT_EQ(ids.size(), n);

  // Bit for bit the in-process pipeline's matrix.
  EXPECT_EQ(Evaluate(stub.get(), "synthetic"), Reference());
}

TEST_F(ServicesTest, KilledAndRestartedIndexAndCoordinatorLoseNoAcknowledgedModel) {
  Stack stack(*dir_ + "/kill-state", 1);
  ASSERT_TRUE(stack.WaitServing());
  auto stub = stack.Coordinator();
  ASSERT_EQ(CreateCollection(stub.get(), "synthetic"), absl::OkStatus());
  const std::size_t n = models_->size();
  std::set<std::string> jobs;
  // Half the models, then the coordinator dies right after acknowledging.
  ASSERT_EQ(Ingest(stub.get(), "synthetic", 0, n / 2, &jobs), n / 2);
  stack.coordinator().Kill(SIGKILL);
  stack.coordinator().Start();
  ASSERT_TRUE(stack.coordinator().WaitServing());
  // The client re-sends everything (idempotent by id) and adds the rest.
  std::set<std::string> jobs2;
  ASSERT_EQ(Ingest(stub.get(), "synthetic", 0, n, &jobs2), n);
  for (const std::string& job : jobs2) {
    const v1::JobStatus status = WaitJob(stub.get(), job);
    EXPECT_EQ(status.state(), v1::JOB_STATE_SUCCEEDED) << status.DebugString();
  }
  EXPECT_TRUE(jobs2.count(*jobs.begin())) << "re-sent models keep their first job";
  // Build while the index is down: its adds fail, are retried, and land once
  // the index is back.
  stack.index().Kill(SIGKILL);
  const std::string build_id = Build(stub.get(), "synthetic");
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));
  stack.index().Start();
  ASSERT_TRUE(stack.index().WaitServing());
  const v1::JobStatus build = WaitJob(stub.get(), build_id);
  ASSERT_EQ(build.state(), v1::JOB_STATE_SUCCEEDED) << build.DebugString();
  EXPECT_EQ(Evaluate(stub.get(), "synthetic"), Reference());

  // Restart both again: the index is restored from its database.
  stack.index().Kill(SIGKILL);
  stack.coordinator().Kill(SIGKILL);
  stack.index().Start();
  stack.coordinator().Start();
  ASSERT_TRUE(stack.index().WaitServing());
  ASSERT_TRUE(stack.coordinator().WaitServing());
  EXPECT_EQ(Evaluate(stub.get(), "synthetic"), Reference());
}

TEST_F(ServicesTest, BadInputGetsTheRightCodeANamedProblemAndServersKeepServing) {
  Stack stack(*dir_ + "/bad-input", 1);
  ASSERT_TRUE(stack.WaitServing());
  auto stub = stack.Coordinator();
  ASSERT_EQ(CreateCollection(stub.get(), "good"), absl::OkStatus());
  // Parameters that name no method: the default fusion, re-ranked (stored
  // with every value, the method first); legacy fields alone keep dld.
  {
    ASSERT_EQ(CreateCollection(stub.get(), "default", v1::PipelineParams()), absl::OkStatus());
    v1::PipelineParams legacy;
    legacy.set_vocabulary(24);
    ASSERT_EQ(CreateCollection(stub.get(), "legacy", legacy), absl::OkStatus());
    for (const auto& [name, method] : std::vector<std::pair<std::string, std::string>>{
             {"default", kDefaultCollectionMethods}, {"legacy", "dld"}}) {
      grpc::ClientContext context;
      v1::GetCollectionRequest request;
      request.set_name(name);
      v1::Collection response;
      ASSERT_TRUE(stub->GetCollection(&context, request, &response).ok());
      ASSERT_GT(response.params().values_size(), 0);
      EXPECT_EQ(response.params().values(0).name(), "method");
      EXPECT_EQ(response.params().values(0).value(), method) << name;
    }
  }

  // Unknown collection.
  {
    grpc::ClientContext context;
    v1::GetCollectionRequest request;
    request.set_name("nope");
    v1::Collection response;
    const grpc::Status status = stub->GetCollection(&context, request, &response);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::NOT_FOUND);
    EXPECT_THAT(status.error_message(), HasSubstr("nope"));
  }
  // Malformed mesh in an ingest stream: the stream ends naming the model.
  {
    grpc::ClientContext context;
    auto stream = stub->Ingest(&context);
    v1::IngestRequest request;
    request.set_collection("good");
    request.set_model_id("broken-17");
    v1::Mesh* mesh = request.mutable_mesh()->mutable_mesh();
    for (float v : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f}) mesh->add_vertices(v);
    for (uint32_t t : {0u, 1u, 9u}) mesh->add_triangles(t);
    stream->Write(request);
    stream->WritesDone();
    v1::IngestAck ack;
    EXPECT_FALSE(stream->Read(&ack));
    const grpc::Status status = stream->Finish();
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
    EXPECT_THAT(status.error_message(), HasSubstr("broken-17"));
    EXPECT_THAT(status.error_message(), HasSubstr("9"));
  }
  // Wrong descriptor size at the codebook (after a real build).
  {
    std::set<std::string> jobs;
    ASSERT_EQ(Ingest(stub.get(), "good", 0, 8, &jobs), 8u);
    WaitJob(stub.get(), *jobs.begin());
    const v1::JobStatus build = WaitJob(stub.get(), Build(stub.get(), "good"));
    ASSERT_EQ(build.state(), v1::JOB_STATE_SUCCEEDED) << build.DebugString();
    auto codebook = v1::Codebook::NewStub(rpc::MakeChannel(Address(stack.codebook().port())));
    grpc::ClientContext context;
    v1::EncodeRequest request;
    request.set_codebook_id("good@" + build.job_id());
    request.mutable_features()->set_count(2);
    request.mutable_features()->set_dimension(128);
    request.mutable_features()->set_descriptors(std::string(200, '\1'));
    v1::EncodeResponse response;
    const grpc::Status status = codebook->Encode(&context, request, &response);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
    EXPECT_THAT(status.error_message(), HasSubstr("200 descriptor bytes"));
  }
  // An over-limit message to an extract worker.
  {
    auto extract = v1::Extract::NewStub(
        grpc::CreateChannel(Address(stack.extract(0).port()), grpc::InsecureChannelCredentials()));
    grpc::ClientContext context;
    v1::ExtractRequest request;
    request.mutable_mesh()->mutable_file()->set_name("huge.off");
    request.mutable_mesh()->mutable_file()->set_data(std::string(65 << 20, ' '));
    v1::ExtractResponse response;
    const grpc::Status status = extract->Extract(&context, request, &response);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED) << status.error_message();
  }
  // Every server still serves, and a query works.
  EXPECT_TRUE(stack.WaitServing());
  // Discovery through reflection (what grpcurl list shows), and the probe.
  {
    const std::string command = std::string(MESHSEEK_SERVICES_DIR) + "/meshseek-probe --addr " +
                                Address(stack.coordinator().port());
    std::string listed;
    FILE* pipe = popen((command + " --list").c_str(), "r");
    char buffer[512];
    while (fgets(buffer, sizeof buffer, pipe) != nullptr) listed += buffer;
    EXPECT_EQ(pclose(pipe), 0);
    EXPECT_THAT(listed, HasSubstr("meshseek.v1.Coordinator"));
    EXPECT_THAT(listed, HasSubstr("grpc.health.v1.Health"));
    EXPECT_EQ(std::system((command + " > /dev/null").c_str()), 0);
  }
  {
    grpc::ClientContext context;
    v1::QueryRequest request;
    request.set_collection("good");
    request.set_top_k(3);
    wire::MeshToProto(*ReadMesh((*models_)[0].path), request.mutable_mesh()->mutable_mesh());
    v1::QueryResponse response;
    const grpc::Status status = stub->Query(&context, request, &response);
    ASSERT_TRUE(status.ok()) << status.error_message();
    ASSERT_EQ(response.results_size(), 3);
    EXPECT_EQ(response.results(0).model_id(), (*models_)[0].id);
    EXPECT_EQ(response.results(0).distance(), 0.0f);
  }
}

// The burst of the hardening issue: 64 concurrent AddModel calls to an index
// with its default 16 server threads were refused ("Server Threadpool
// Exhausted"); now they wait in the server's queue and all succeed.
TEST(ServicesLoadTest, SixtyFourConcurrentAddModelCallsToTheIndexAllSucceed) {
  const std::string dir = ::testing::TempDir() + "/meshseek_index_burst";
  std::filesystem::remove_all(dir);
  Server index("index", {"--data_dir=" + dir});
  ASSERT_TRUE(index.WaitServing());
  auto stub = v1::Index::NewStub(rpc::MakeChannel(Address(index.port())));
  constexpr int kCalls = 64;
  std::vector<grpc::Status> statuses(kCalls);
  std::vector<std::thread> clients;
  for (int i = 0; i < kCalls; ++i) {
    clients.emplace_back([&, i] {
      grpc::ClientContext context;
      rpc::SetDeadline(&context, absl::Seconds(60));
      v1::AddModelRequest request;
      request.set_collection("burst");
      request.set_model_id(absl::StrCat("m", i));
      request.set_ordinal(i);
      request.mutable_histogram()->set_size(16);
      request.mutable_histogram()->add_bins(i % 16);
      request.mutable_histogram()->add_weights(1.0f);
      v1::AddModelResponse response;
      statuses[i] = stub->AddModel(&context, request, &response);
    });
  }
  for (auto& c : clients) c.join();
  for (int i = 0; i < kCalls; ++i) {
    EXPECT_TRUE(statuses[i].ok()) << "call " << i << ": " << statuses[i].error_code() << " "
                                  << statuses[i].error_message();
  }
}

// A collection of a global method (LFD): no codebook, one descriptor per
// model in the index, ranked by the method's distance; over two shards, with
// the index and the coordinator killed, it gives the in-process matrix.
TEST_F(ServicesTest, AGlobalDescriptorCollectionSurvivesKillsAndEqualsInProcess) {
  v1::PipelineParams params;
  v1::ParamValue* method = params.add_values();
  method->set_name("method");
  method->set_value("lfd");
  auto options = wire::PipelineOptionsFromParams(params);
  ASSERT_TRUE(options.ok()) << options.status();
  // A third of the models (three classes): LFD renders 100 views per model,
  // slow under the sanitizers.
  const std::size_t n = models_->size() / 3;
  const std::vector<ManifestEntry> models(models_->begin(), models_->begin() + n);
  auto reference = EvaluateCollection(models, CollectionOptions::Of(*options));
  ASSERT_TRUE(reference.ok()) << reference.status();
  EXPECT_EQ(reference->methods[0].codebook_size, 0u);

  Stack stack(*dir_ + "/global", 1, 512, /*index_shards=*/2);
  ASSERT_TRUE(stack.WaitServing());
  auto stub = stack.Coordinator();
  ASSERT_EQ(CreateCollection(stub.get(), "lfd", params), absl::OkStatus());
  std::set<std::string> jobs;
  ASSERT_EQ(Ingest(stub.get(), "lfd", 0, n, &jobs), n);
  for (const std::string& job : jobs) {
    EXPECT_EQ(WaitJob(stub.get(), job).state(), v1::JOB_STATE_SUCCEEDED);
  }
  stack.index(0).Kill(SIGKILL);  // the build's adds are retried until it is back
  const std::string build_id = Build(stub.get(), "lfd");
  std::this_thread::sleep_for(std::chrono::milliseconds(1000));
  stack.index(0).Start();
  ASSERT_TRUE(stack.index(0).WaitServing());
  const v1::JobStatus build = WaitJob(stub.get(), build_id);
  ASSERT_EQ(build.state(), v1::JOB_STATE_SUCCEEDED) << build.DebugString();
  EXPECT_EQ(Evaluate(stub.get(), "lfd", n), reference->distances);

  // Restored from the databases after kill -9.
  stack.index(0).Kill(SIGKILL);
  stack.index(1).Kill(SIGKILL);
  stack.coordinator().Kill(SIGKILL);
  stack.index(0).Start();
  stack.index(1).Start();
  stack.coordinator().Start();
  ASSERT_TRUE(stack.WaitServing());
  EXPECT_EQ(Evaluate(stub.get(), "lfd", n), reference->distances);
  // A query is its model's row of the matrix: itself first at distance 0.
  v1::QueryResponse response;
  const grpc::Status status = Query(stub.get(), "lfd", 5, 3, absl::Seconds(60), &response);
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_EQ(response.results_size(), 3);
  EXPECT_EQ(response.results(0).model_id(), (*models_)[5].id);
  EXPECT_EQ(response.results(0).distance(), 0.0f);
  EXPECT_EQ(response.results(1).distance(), [&] {
    std::vector<float> row(reference->distances.begin() + 5 * n,
                           reference->distances.begin() + 6 * n);
    std::sort(row.begin(), row.end());
    return row[1];
  }());
  // Candidates cannot act on one global method: an error, never ignored.
  {
    grpc::ClientContext context;
    rpc::SetDeadline(&context, absl::Seconds(60));
    v1::QueryRequest request;
    request.set_collection("lfd");
    request.set_top_k(3);
    request.set_candidates(10);
    request.set_model_id((*models_)[0].id);
    v1::QueryResponse ignored;
    const grpc::Status refused = stub->Query(&context, request, &ignored);
    EXPECT_EQ(refused.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
    EXPECT_THAT(refused.error_message(), HasSubstr("candidates=10 does not apply"));
  }
}

// A fused, re-ranked collection (LSF + LFD, small settings, LSF's codebook
// trained on a sample of its features): each model
// stored in both members, each extracted with its method, the build builds
// both and the ranking state; over two shards, with the coordinator killed
// during the build, Evaluate gives the in-process matrix bit for bit. A
// model ingested afterwards is searchable with no build (live ingest).
TEST_F(ServicesTest, AFusedRerankedCollectionSurvivesKillsAndEqualsInProcess) {
  v1::PipelineParams params;
  for (const auto& [name, value] : std::vector<std::pair<std::string, std::string>>{
           {"method", "lsf+lfd"},
           {"points", "128"},
           {"vocabulary", "64"},
           // 2,560 of LSF's ~6,000 features train: the build sends the codebook
           // service that sample only (KMeansOptions::sampled_from).
           {"kmeans_points_per_centroid", "40"},
           {"view_size", "64"},
           {"histogram_power", "0.5"},  // LSF's histograms square-rooted, in the coordinator
           {"rerank_k1", "5"},
           {"rerank_k2", "2"},
           {"rerank_depth", "20"}}) {
    v1::ParamValue* v = params.add_values();
    v->set_name(name);
    v->set_value(value);
  }
  auto options = wire::CollectionOptionsFromParams(params);
  ASSERT_TRUE(options.ok()) << options.status();
  ASSERT_TRUE(options->fused() && options->rerank.enabled());
  const std::size_t n = models_->size() / 3;
  const std::vector<ManifestEntry> models(models_->begin(), models_->begin() + n);
  CollectionOptions in_process = *options;
  in_process.SetRunOptions(2, false);
  auto reference = EvaluateCollection(models, in_process);
  ASSERT_TRUE(reference.ok()) << reference.status();

  Stack stack(*dir_ + "/fused", 1, 512, /*index_shards=*/2);
  // One shard frees its postings past 4 models: its full rows then come
  // from the forward file (kl_inverted_index.h, "Storage"), and every matrix
  // below must still be the in-process one bit for bit.
  stack.index(0).Kill(SIGKILL);
  stack.index(0).AddArgs({"--postings_max_models=4"});
  stack.index(0).Start();
  ASSERT_TRUE(stack.WaitServing());
  auto stub = stack.Coordinator();
  ASSERT_EQ(CreateCollection(stub.get(), "fused", params), absl::OkStatus());
  {
    // idf needs document frequencies over the whole collection, which the
    // services do not keep: refused by name rather than served unweighted.
    v1::PipelineParams with_idf = params;
    v1::ParamValue* idf = with_idf.add_values();
    idf->set_name("idf");
    idf->set_value("true");
    const absl::Status refused = CreateCollection(stub.get(), "with-idf", with_idf);
    EXPECT_EQ(refused.code(), absl::StatusCode::kInvalidArgument);
    EXPECT_THAT(std::string(refused.message()), HasSubstr("idf=true"));
  }
  std::set<std::string> jobs;
  ASSERT_EQ(Ingest(stub.get(), "fused", 0, n, &jobs), n);
  for (const std::string& job : jobs) {
    EXPECT_EQ(WaitJob(stub.get(), job).state(), v1::JOB_STATE_SUCCEEDED);
  }
  // The members are the coordinator's: clients use the fused collection.
  {
    grpc::ClientContext context;
    v1::BuildRequest request;
    request.set_collection("fused~lsf");
    v1::JobStatus status;
    EXPECT_EQ(stub->Build(&context, request, &status).error_code(),
              grpc::StatusCode::INVALID_ARGUMENT);
  }
  const std::string build_id = Build(stub.get(), "fused");
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  stack.coordinator().Kill(SIGKILL);  // mid-build: resumed at the restart
  stack.coordinator().Start();
  ASSERT_TRUE(stack.WaitServing());
  const v1::JobStatus build = WaitJob(stub.get(), build_id);
  ASSERT_EQ(build.state(), v1::JOB_STATE_SUCCEEDED) << build.DebugString();
  EXPECT_EQ(Evaluate(stub.get(), "fused", n), reference->distances);

  // Restored after kill -9 of everything that holds state.
  stack.index(0).Kill(SIGKILL);
  stack.index(1).Kill(SIGKILL);
  stack.coordinator().Kill(SIGKILL);
  stack.index(0).Start();
  stack.index(1).Start();
  stack.coordinator().Start();
  ASSERT_TRUE(stack.WaitServing());
  EXPECT_EQ(Evaluate(stub.get(), "fused", n), reference->distances);

  // Live ingest: a model ingested into the built collection, the
  // coordinator killed right after acknowledging it, is its own first result
  // within 2 s of its extraction ending, with no build.
  {
    std::set<std::string> live_jobs;
    ASSERT_EQ(Ingest(stub.get(), "fused", n, n + 1, &live_jobs), 1u);
    stack.coordinator().Kill(SIGKILL);
    stack.coordinator().Start();
    ASSERT_TRUE(stack.WaitServing());
    ASSERT_EQ(live_jobs.size(), 1u);
    ASSERT_EQ(WaitJob(stub.get(), *live_jobs.begin()).state(), v1::JOB_STATE_SUCCEEDED);
    const absl::Time extracted = absl::Now();
    v1::QueryResponse found;
    while (absl::Now() - extracted < absl::Seconds(2 * kSlowdown)) {
      found.Clear();
      if (Query(stub.get(), "fused", n, 3, absl::Seconds(10), &found).ok() &&
          found.results_size() > 0 && found.results(0).model_id() == (*models_)[n].id) {
        break;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    ASSERT_GT(found.results_size(), 0);
    EXPECT_EQ(found.results(0).model_id(), (*models_)[n].id)
        << "not searchable " << absl::FormatDuration(absl::Now() - extracted)
        << " after its extraction ended";
    // The stages apart, one entry per member in the collection's order.
    ASSERT_EQ(found.timings().methods_size(), static_cast<int>(options->methods.size()));
    for (int m = 0; m < found.timings().methods_size(); ++m) {
      EXPECT_EQ(found.timings().methods(m).method(),
                FeatureMethodName(options->methods[m].extractor.method));
      EXPECT_GT(found.timings().methods(m).extract_seconds(), 0);
    }
    EXPECT_GT(found.timings().signatures_seconds(), 0);
    EXPECT_GT(found.timings().search_seconds(), 0);
    grpc::ClientContext context;
    v1::GetCollectionRequest get;
    get.set_name("fused");
    v1::Collection info;
    ASSERT_TRUE(stub->GetCollection(&context, get, &info).ok());
    EXPECT_EQ(info.indexed(), n + 1);
    EXPECT_EQ(info.added_since_build(), 1u);
    // Restarted again, the join is replayed from the store.
    stack.coordinator().Kill(SIGKILL);
    stack.coordinator().Start();
    ASSERT_TRUE(stack.WaitServing());
    // The test's channel saw the coordinator's port refuse connections while
    // it was down and may still be in reconnect backoff when the restarted one
    // serves: without wait_for_ready the first query then failed at once,
    // about once in ten runs, with UNAVAILABLE ("connections to all backends
    // failing ... Connection refused").
    found.Clear();
    const grpc::Status replayed =
        Query(stub.get(), "fused", n, 3, absl::Seconds(60), &found, /*wait_for_ready=*/true);
    ASSERT_TRUE(replayed.ok()) << replayed.error_code() << ": " << replayed.error_message();
    ASSERT_GT(found.results_size(), 0);
    EXPECT_EQ(found.results(0).model_id(), (*models_)[n].id);
  }
  // Fused candidates (two index shards): each member proposes, the union is
  // fused and re-ranked. Candidates covering the collection give the exact
  // answer bit for bit; a few still find the model itself first.
  {
    const auto query = [&](uint32_t candidates, uint32_t top_k) {
      grpc::ClientContext context;
      rpc::SetDeadline(&context, absl::Seconds(60));
      v1::QueryRequest request;
      request.set_collection("fused");
      request.set_top_k(top_k);
      request.set_candidates(candidates);
      request.set_model_id((*models_)[2].id);
      v1::QueryResponse response;
      const grpc::Status status = stub->Query(&context, request, &response);
      EXPECT_TRUE(status.ok()) << status.error_message();
      return response;
    };
    const v1::QueryResponse exact = query(0, 8);
    const v1::QueryResponse covering = query(n + 1, 8);
    ASSERT_EQ(covering.results_size(), exact.results_size());
    for (int r = 0; r < exact.results_size(); ++r) {
      EXPECT_EQ(covering.results(r).model_id(), exact.results(r).model_id()) << r;
      EXPECT_EQ(covering.results(r).distance(), exact.results(r).distance()) << r;
    }
    const v1::QueryResponse few = query(2, 3);
    ASSERT_GE(few.results_size(), 1);
    EXPECT_EQ(few.results(0).model_id(), (*models_)[2].id);
    EXPECT_LE(few.results_size(), 3);
    grpc::ClientContext context;
    v1::QueryRequest request;
    request.set_collection("fused");
    request.set_top_k(3);
    request.set_candidates(8193);  // one past kMaxFusedCandidates
    request.set_model_id((*models_)[2].id);
    v1::QueryResponse unanswered;
    const grpc::Status refused = stub->Query(&context, request, &unanswered);
    EXPECT_EQ(refused.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
    EXPECT_THAT(refused.error_message(), HasSubstr("at most 8192"));
  }

  // Bounded storage: each mesh once, and no features kept once a model is
  // indexed and ranked (the build extracts them again from the meshes).
  const auto stored = [&](const std::string& what) {
    auto db = Database::Open(*dir_ + "/fused/coordinator/coordinator.db");
    EXPECT_TRUE(db.ok()) << db.status();
    auto select = (*db)->Prepare(absl::StrCat("SELECT ", what, " FROM models"));
    EXPECT_TRUE(select.ok() && select->Run().ok());
    return select->ColumnInt(0);
  };
  const auto feature_files = [&] {
    std::size_t files = 0;
    for (const auto& entry :
         std::filesystem::recursive_directory_iterator(*dir_ + "/fused/coordinator/features")) {
      files += entry.is_regular_file();
    }
    return files;
  };
  EXPECT_EQ(stored("COALESCE(SUM(length(features)), 0)"), 0);
  EXPECT_EQ(feature_files(), 0u);
  EXPECT_EQ(stored("SUM(length(mesh) > 0)"), static_cast<int64_t>(n + 1));
  EXPECT_EQ(stored("COUNT(*)"), static_cast<int64_t>(2 * (n + 1)));
  // A rebuild (features extracted again, the live model trained on too)
  // gives the in-process matrix of every model, bit for bit; its graph made
  // from candidates (the approximate graph of large collections), which give
  // the exact one when they cover the collection.
  {
    stack.coordinator().Kill(SIGKILL);
    stack.coordinator().AddArgs(
        {"--exact_graph_models=0", absl::StrCat("--graph_candidates=", n + 1)});
    stack.coordinator().Start();
    ASSERT_TRUE(stack.WaitServing());
    const std::vector<ManifestEntry> grown(models_->begin(), models_->begin() + n + 1);
    auto rebuilt = EvaluateCollection(grown, in_process);
    ASSERT_TRUE(rebuilt.ok()) << rebuilt.status();
    const v1::JobStatus again = WaitJob(stub.get(), Build(stub.get(), "fused"));
    ASSERT_EQ(again.state(), v1::JOB_STATE_SUCCEEDED) << again.DebugString();
    EXPECT_EQ(Evaluate(stub.get(), "fused", n + 1), rebuilt->distances);
    EXPECT_EQ(feature_files(), 0u);
  }

  // A model queried joins the graph beside its stored copy: that copy first.
  v1::QueryResponse response;
  grpc::Status status = Query(stub.get(), "fused", 4, 3, absl::Seconds(60), &response);
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_EQ(response.results_size(), 3);
  EXPECT_EQ(response.results(0).model_id(), (*models_)[4].id);
  EXPECT_GT(response.query_features(), 1u);  // LSF's features and LFD's one descriptor

  // Removed from both members: it ranks nowhere until the next build.
  {
    grpc::ClientContext context;
    v1::RemoveModelFromCollectionRequest remove;
    remove.set_collection("fused");
    remove.set_model_id((*models_)[4].id);
    v1::RemoveModelFromCollectionResponse removed;
    ASSERT_TRUE(stub->RemoveModel(&context, remove, &removed).ok());
    EXPECT_TRUE(removed.removed());
  }
  status = Query(stub.get(), "fused", 4, 3, absl::Seconds(60), &response);
  ASSERT_TRUE(status.ok()) << status.error_message();
  for (const v1::ScoredModel& m : response.results()) EXPECT_NE(m.model_id(), (*models_)[4].id);

  // A live ingest into the collection whose graph came from candidates
  // joins it from candidates too: its own first result.
  std::set<std::string> late;
  ASSERT_EQ(Ingest(stub.get(), "fused", n + 1, n + 2, &late), 1u);
  ASSERT_EQ(WaitJob(stub.get(), *late.begin()).state(), v1::JOB_STATE_SUCCEEDED);
  const absl::Time extracted = absl::Now();
  do {
    response.Clear();
    status = Query(stub.get(), "fused", n + 1, 3, absl::Seconds(60), &response);
  } while (status.ok() && (response.results_size() == 0 ||
                           response.results(0).model_id() != (*models_)[n + 1].id) &&
           absl::Now() - extracted < absl::Seconds(2 * kSlowdown));
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_GT(response.results_size(), 0);
  EXPECT_EQ(response.results(0).model_id(), (*models_)[n + 1].id);
}

TEST_F(ServicesTest, TwoIndexShardsGiveTheResultsOfOneAndNeverAPartialAnswer) {
  Stack stack(*dir_ + "/shards", 1, 512, /*index_shards=*/2);
  ASSERT_TRUE(stack.WaitServing());
  auto stub = stack.Coordinator();
  ASSERT_EQ(CreateCollection(stub.get(), "synthetic"), absl::OkStatus());
  const std::size_t n = models_->size();
  std::set<std::string> jobs;
  ASSERT_EQ(Ingest(stub.get(), "synthetic", 0, n, &jobs), n);
  WaitJob(stub.get(), *jobs.begin());
  const v1::JobStatus build = WaitJob(stub.get(), Build(stub.get(), "synthetic"));
  ASSERT_EQ(build.state(), v1::JOB_STATE_SUCCEEDED) << build.DebugString();

  // Each model on exactly one shard, both shards used.
  std::set<std::string> placed;
  std::size_t total = 0;
  for (int s = 0; s < 2; ++s) {
    auto index = v1::Index::NewStub(rpc::MakeChannel(Address(stack.index(s).port())));
    grpc::ClientContext context;
    v1::ListModelsRequest list;
    list.set_collection("synthetic");
    v1::ListModelsResponse listed;
    ASSERT_TRUE(index->ListModels(&context, list, &listed).ok());
    EXPECT_GT(listed.model_ids_size(), static_cast<int>(n / 4)) << "shard " << s;
    total += listed.model_ids_size();
    placed.insert(listed.model_ids().begin(), listed.model_ids().end());
  }
  EXPECT_EQ(total, n);
  EXPECT_EQ(placed.size(), n);

  // The merged matrix and top-k are the one-index results, bit for bit.
  EXPECT_EQ(Evaluate(stub.get(), "synthetic"), Reference());
  for (std::size_t i : {std::size_t{0}, n / 4, n - 1}) {
    v1::QueryResponse response;
    const grpc::Status status = Query(stub.get(), "synthetic", i, 7, absl::Seconds(30), &response);
    ASSERT_TRUE(status.ok()) << status.error_message();
    EXPECT_EQ(Results(response), ReferenceTop(i, 7)) << "query " << i;
  }

  // A shard that is down: the query fails (here at the client's deadline,
  // while the coordinator retries), it does not answer from one shard.
  stack.index(1).Kill(SIGKILL);
  {
    v1::QueryResponse response;
    const grpc::Status status = Query(stub.get(), "synthetic", 0, 7, absl::Seconds(3), &response);
    EXPECT_FALSE(status.ok()) << Results(response).size() << " results from one shard";
    EXPECT_THAT(status.error_code(), ::testing::AnyOf(grpc::StatusCode::UNAVAILABLE,
                                                      grpc::StatusCode::DEADLINE_EXCEEDED));
  }
  // A shard restarting while a query waits: the retry gets the full answer.
  std::thread restart([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(800));
    stack.index(1).Start();
  });
  {
    v1::QueryResponse response;
    const grpc::Status status = Query(stub.get(), "synthetic", n / 4, 7, absl::Seconds(60), &response);
    ASSERT_TRUE(status.ok()) << status.error_message();
    EXPECT_EQ(Results(response), ReferenceTop(n / 4, 7));
  }
  restart.join();
  EXPECT_EQ(Evaluate(stub.get(), "synthetic"), Reference());

  // The coordinator refuses to run with another number of shards.
  stack.coordinator().Kill(SIGKILL);
  Server other("coordinator",
               {"--data_dir=" + *dir_ + "/shards/coordinator", "--resample=127.0.0.1:1",
                "--extract=127.0.0.1:1", "--codebook=127.0.0.1:1",
                "--index=" + Address(stack.index(0).port())});
  EXPECT_GT(other.WaitExit(absl::Seconds(20)), 0);
}

// A model whose extraction keeps failing (here: every extract worker is
// gone) ends FAILED with its reason within seconds, `meshseek status` lists
// it, the coordinator then idles, and a build goes on without it.
TEST_F(ServicesTest, AModelThatCannotBeExtractedEndsFailedAndTheBuildGoesOnWithoutIt) {
  Stack stack(*dir_ + "/failing", 1, 512, 1,
              {"--model_attempts=2", "--call_attempts=2", "--retry_backoff=200ms"});
  ASSERT_TRUE(stack.WaitServing());
  auto stub = stack.Coordinator();
  ASSERT_EQ(CreateCollection(stub.get(), "failing"), absl::OkStatus());
  std::set<std::string> jobs;
  ASSERT_EQ(Ingest(stub.get(), "failing", 0, 6, &jobs), 6u);
  EXPECT_EQ(WaitJob(stub.get(), *jobs.begin()).state(), v1::JOB_STATE_SUCCEEDED);

  stack.extract(0).Kill(SIGKILL);
  jobs.clear();
  const absl::Time start = absl::Now();
  ASSERT_EQ(Ingest(stub.get(), "failing", 6, 7, &jobs), 1u);
  const v1::JobStatus ingest = WaitJob(stub.get(), *jobs.begin());
  const absl::Duration took = absl::Now() - start;
  EXPECT_EQ(ingest.state(), v1::JOB_STATE_FAILED);
  ASSERT_EQ(ingest.errors_size(), 1);
  EXPECT_THAT(ingest.errors(0), HasSubstr("gave up after 2 attempts: UNAVAILABLE"));
  EXPECT_LT(took, absl::Seconds(15 * kSlowdown));
  std::printf("unextractable model FAILED %.1f s after its ingest\n", absl::ToDoubleSeconds(took));

  // What scripts read: `meshseek status --format json` (never the text).
  std::string status;
  {
    const std::string command = absl::StrCat(MESHSEEK_CLI_PATH, " status --format json --server ",
                                              Address(stack.coordinator().port()),
                                              " --collection failing");
    FILE* pipe = popen(command.c_str(), "r");
    char buffer[512];
    while (fgets(buffer, sizeof buffer, pipe) != nullptr) status += buffer;
    EXPECT_EQ(pclose(pipe), 0);
  }
  std::printf("meshseek status --format json:\n%s", status.c_str());
  // Fields by the proto's names; uint64 counts are strings in protobuf's JSON
  // mapping.
  EXPECT_THAT(status, HasSubstr("\"models\":\"7\""));
  EXPECT_THAT(status, HasSubstr("\"pending\":\"0\""));
  EXPECT_THAT(status, HasSubstr("\"extracted\":\"6\""));
  EXPECT_THAT(status, HasSubstr("\"failed\":\"1\""));
  EXPECT_THAT(status, HasSubstr(absl::StrCat("\"failed_models\":[{\"model_id\":\"", (*models_)[6].id,
                                             "\"")));
  EXPECT_THAT(status, HasSubstr("\"state\":\"MODEL_STATE_FAILED\""));
  EXPECT_THAT(status, HasSubstr("\"attempts\":2,\"error\":\"gave up after 2 attempts"));
  // The canonical parameters only: no zeroed legacy field beside them.
  EXPECT_THAT(status, Not(HasSubstr("FEATURE_METHOD_UNSPECIFIED")));
  EXPECT_THAT(status, Not(HasSubstr("\"vocabulary\":0")));

  // Nothing left to retry: the coordinator idles.
  const double cpu = CpuSeconds(stack.coordinator().pid());
  std::this_thread::sleep_for(std::chrono::seconds(2));
  const double idle_cpu = CpuSeconds(stack.coordinator().pid()) - cpu;
  EXPECT_LT(idle_cpu, 0.1 * kSlowdown) << "CPU seconds in 2 s with nothing to do";
  std::printf("coordinator CPU while idle: %.2f s in 2 s\n", idle_cpu);

  stack.extract(0).Start();
  ASSERT_TRUE(stack.extract(0).WaitServing());
  const v1::JobStatus build = WaitJob(stub.get(), Build(stub.get(), "failing"));
  EXPECT_EQ(build.state(), v1::JOB_STATE_SUCCEEDED) << build.DebugString();
  EXPECT_THAT(build.message(), HasSubstr("6 models indexed"));
  EXPECT_THAT(build.message(), HasSubstr("1 failed models left out"));
}

// What the web page stands on: every model has its thumbnail as soon as it
// is acknowledged (drawn at ingest, before extraction), the list of
// collections hides fused collections' members, a model of the collection
// can be the query, and a removed model's thumbnail goes with it. A model
// stored before there were thumbnails gets one drawn from its stored mesh.
TEST_F(ServicesTest, ThumbnailsListingAndQueriesByModelServeTheWebPage) {
  const std::string dir = *dir_ + "/thumbnails";
  auto stack = std::make_unique<Stack>(dir, 1);
  ASSERT_TRUE(stack->WaitServing());
  auto stub = stack->Coordinator();
  ASSERT_EQ(CreateCollection(stub.get(), "pictures"), absl::OkStatus());
  v1::PipelineParams fused;
  v1::ParamValue* method = fused.add_values();
  method->set_name("method");
  method->set_value("lsf+lfd");
  ASSERT_EQ(CreateCollection(stub.get(), "both", fused), absl::OkStatus());
  std::set<std::string> jobs;
  ASSERT_EQ(Ingest(stub.get(), "pictures", 0, 8, &jobs), 8u);

  auto thumbnail = [&](const std::string& id, v1::Thumbnail* png) {
    grpc::ClientContext context;
    rpc::SetDeadline(&context, absl::Seconds(10));
    v1::GetThumbnailRequest request;
    request.set_collection("pictures");
    request.set_model_id(id);
    return stub->GetThumbnail(&context, request, png);
  };
  const std::string& first = (*models_)[0].id;
  v1::Thumbnail png;
  ASSERT_TRUE(thumbnail(first, &png).ok());
  EXPECT_EQ(png.png().substr(1, 3), "PNG");
  EXPECT_GT(png.png().size(), 1000u);
  EXPECT_EQ(thumbnail("no-such-model", &png).error_code(), grpc::StatusCode::NOT_FOUND);

  {
    grpc::ClientContext context;
    rpc::SetDeadline(&context, absl::Seconds(10));
    v1::ListCollectionsResponse list;
    ASSERT_TRUE(stub->ListCollections(&context, v1::ListCollectionsRequest(), &list).ok());
    std::vector<std::string> names;
    for (const v1::Collection& c : list.collections()) names.push_back(c.name());
    EXPECT_THAT(names, ::testing::ElementsAre("both", "pictures"));
    EXPECT_EQ(list.collections(1).models(), 8u);
  }

  ASSERT_EQ(WaitJob(stub.get(), *jobs.begin()).state(), v1::JOB_STATE_SUCCEEDED);
  ASSERT_EQ(WaitJob(stub.get(), Build(stub.get(), "pictures")).state(), v1::JOB_STATE_SUCCEEDED);
  auto query = [&](v1::QueryRequest request, v1::QueryResponse* response) {
    grpc::ClientContext context;
    rpc::SetDeadline(&context, absl::Seconds(30));
    request.set_collection("pictures");
    request.set_top_k(3);
    return stub->Query(&context, request, response);
  };
  v1::QueryRequest by_model;
  by_model.set_model_id((*models_)[3].id);
  v1::QueryResponse ranked;
  ASSERT_TRUE(query(by_model, &ranked).ok());
  ASSERT_EQ(ranked.results_size(), 3);
  EXPECT_EQ(ranked.results(0).model_id(), (*models_)[3].id);
  EXPECT_EQ(ranked.results(0).distance(), 0.0f);
  v1::QueryRequest both = by_model;
  wire::MeshToProto(*ReadMesh((*models_)[3].path), both.mutable_mesh()->mutable_mesh());
  EXPECT_EQ(query(both, &ranked).error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  by_model.set_model_id("no-such-model");
  EXPECT_EQ(query(by_model, &ranked).error_code(), grpc::StatusCode::NOT_FOUND);

  {
    grpc::ClientContext context;
    rpc::SetDeadline(&context, absl::Seconds(10));
    v1::RemoveModelFromCollectionRequest remove;
    remove.set_collection("pictures");
    remove.set_model_id(first);
    v1::RemoveModelFromCollectionResponse removed;
    ASSERT_TRUE(stub->RemoveModel(&context, remove, &removed).ok());
  }
  EXPECT_EQ(thumbnail(first, &png).error_code(), grpc::StatusCode::NOT_FOUND);

  // As an earlier release left it: models without thumbnails.
  stack.reset();
  {
    auto db = Database::Open(dir + "/coordinator/coordinator.db");
    ASSERT_TRUE(db.ok()) << db.status();
    ASSERT_TRUE((*db)->Execute("DELETE FROM thumbnails").ok());
  }
  stack = std::make_unique<Stack>(dir, 1);
  ASSERT_TRUE(stack->WaitServing());
  stub = stack->Coordinator();
  ASSERT_TRUE(thumbnail((*models_)[1].id, &png).ok());
  EXPECT_EQ(png.png().substr(1, 3), "PNG");
}

}  // namespace
}  // namespace meshseek
