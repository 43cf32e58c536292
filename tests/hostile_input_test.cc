// Hostile input against the public surface: a corpus of malformed mesh files
// (each class the hardening issue found, and more) sent as MeshFile through
// Ingest and Query to a running `meshseek serve`, and read by the CLI. Every
// bad file must be refused with INVALID_ARGUMENT naming the file within a
// second, every valid one accepted, and the server must still serve, with
// resident memory under 1 GB, at the end.
#include <unistd.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/time/clock.h"
#include "common/base/test_env.h"
#include "common/rpc/client.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/server_process.h"
#include "meshseek/v1/coordinator.grpc.pb.h"

namespace meshseek {
namespace {

using ::testing::HasSubstr;

struct MeshCase {
  std::string name;
  std::string bytes;
};

std::string LittleEndian32(uint32_t v) {
  std::string out(4, '\0');
  for (int i = 0; i < 4; ++i) out[i] = static_cast<char>(v >> (8 * i));
  return out;
}

std::string Float32(float f) {
  uint32_t bits;
  std::memcpy(&bits, &f, 4);
  return LittleEndian32(bits);
}

const char* kTetrahedronOff =
    "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";

// Files that must be refused, one per class of trouble.
std::vector<MeshCase> HostileFiles() {
  std::vector<MeshCase> files = {
      {"empty.off", ""},
      {"bare-header.off", "OFF"},
      {"bare-header-newline.off", "OFF\n"},
      {"counts-in-billions.off", "OFF\n4000000000 4000000000 0\n"},
      {"count-overflows-64-bits.off", "OFF\n99999999999999999999999 1 0\n0 0 0\n"},
      {"negative-counts.off", "OFF\n-3 -1 0\n"},
      {"face-with-billions-of-corners.off",
       "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n2000000000 0 1 2\n"},
      {"face-list-cut-short.off",
       "OFF\n4 3 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 1 2\n3 0 1 3\n"},
      {"vertex-list-cut-short.off", "OFF\n4 1 0\n0 0 0\n1 0 0\n"},
      {"index-out-of-range.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n"},
      {"area-overflows-to-infinity.off",
       "OFF\n3 1 0\n-3e38 -3e38 0\n3e38 -3e38 0\n0 3e38 0\n3 0 1 2\n"},
      {"nan-coordinate.off", "OFF\n3 1 0\nnan 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"},
      {"no-faces.off", "OFF\n3 0 0\n0 0 0\n1 0 0\n0 1 0\n"},
      {"infinite-coordinate.obj", "v inf 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"},
      {"index-out-of-range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n"},
      {"index-zero.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n"},
      {"garbage-numbers.obj", "v 0 0 zero\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"},
      {"binary-zeros.obj", std::string(256, '\0')},
      {"huge-elements.ply",
       "ply\nformat binary_little_endian 1.0\nelement vertex 4294967295\nproperty float x\n"
       "property float y\nproperty float z\nelement face 4294967295\n"
       "property list uchar int vertex_indices\nend_header\n" +
           std::string(64, '\1')},
      {"list-longer-than-file.ply",
       "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
       "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
       "0 0 0\n1 0 0\n0 1 0\n255 0 1 2\n"},
      {"no-end-header.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"},
      {"unknown-property-type.ply",
       "ply\nformat ascii 1.0\nelement vertex 3\nproperty quux x\nend_header\n0\n0\n0\n"},
      {"lying-triangle-count.stl",
       std::string(80, ' ') + LittleEndian32(1000000000) + std::string(50, '\0')},
      {"ascii-cut-short.stl", "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1"},
      {"not-a-mesh.txt", "hello, world\n"},
  };
  // A binary STL whose one triangle has a NaN corner.
  std::string stl = std::string(80, ' ') + LittleEndian32(1) + std::string(12, '\0');
  for (float f : {std::nanf(""), 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f}) stl += Float32(f);
  files.push_back({"nan-corner.stl", stl + std::string(2, '\0')});
  // Random bytes under each extension.
  uint64_t state = 42;
  for (const char* ext : {".off", ".obj", ".ply", ".stl"}) {
    std::string noise(300, '\0');
    for (char& c : noise) {
      state = state * 6364136223846793005ull + 1442695040888963407ull;
      c = static_cast<char>(state >> 56);
    }
    files.push_back({absl::StrCat("random-bytes", ext), noise});
  }
  return files;
}

// Files that must be read, including ones the first release refused or
// misread.
std::vector<MeshCase> ValidFiles() {
  return {
      {"tetrahedron.off", kTetrahedronOff},
      {"comments-before-header.off", std::string("# written by hand\n# and commented\n") +
                                         kTetrahedronOff},
      {"off-content-named.obj", kTetrahedronOff},
      {"octahedron.obj",
       "v 1 0 0\nv -1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nv 0 0 -1\n"
       "f 1 3 5\nf 3 2 5\nf 2 4 5\nf 4 1 5\nf 3 1 6\nf 2 3 6\nf 4 2 6\nf 1 4 6\n"},
      {"pyramid-with-quad.ply",
       "ply\nformat ascii 1.0\nelement vertex 5\nproperty float x\nproperty float y\n"
       "property float z\nelement face 5\nproperty list uchar int vertex_indices\nend_header\n"
       "0 0 0\n1 0 0\n1 1 0\n0 1 0\n0.5 0.5 1\n4 0 3 2 1\n3 0 1 4\n3 1 2 4\n3 2 3 4\n3 3 0 4\n"},
      {"triangle.stl",
       "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
       "endloop\nendfacet\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 0 1 0\n"
       "vertex 0 0 1\nendloop\nendfacet\nendsolid t\n"},
  };
}


// Resident memory of a process, in MiB (VmRSS).
double ResidentMiB(pid_t pid) {
  std::ifstream status(absl::StrCat("/proc/", pid, "/status"));
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("VmRSS:", 0) == 0) return std::stod(line.substr(6)) / 1024.0;
  }
  return -1;
}

// Runs the CLI with its address space bounded to 4 GiB (a reader that
// allocated what a lying header promises fails here instead of swapping the
// machine), returning its exit code and stderr+stdout. Not under
// AddressSanitizer or ThreadSanitizer, whose shadow memory reserves terabytes
// of address space (they catch such allocations themselves).
constexpr const char* kAddressSpaceLimit = kSanitized ? "" : "ulimit -v 4194304; ";
int RunCli(const std::string& args, std::string* output) {
  FILE* pipe = popen(
      (kAddressSpaceLimit + std::string(MESHSEEK_CLI_PATH) + " " + args + " 2>&1").c_str(), "r");
  char buffer[512];
  output->clear();
  while (fgets(buffer, sizeof buffer, pipe) != nullptr) *output += buffer;
  const int status = pclose(pipe);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128;
}

class HostileInputTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = ::testing::TempDir() + "/meshseek_hostile";
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_ + "/files");
    server_ = std::make_unique<ServerProcess>(
        std::vector<std::string>{MESHSEEK_CLI_PATH, "serve", "--data_dir=" + dir_ + "/data",
                                 "--threads=2"},
        dir_ + "/serve.log", "meshseek serving on 127.0.0.1:");
    ASSERT_TRUE(server_->WaitServing()) << "meshseek serve did not start";
    channel_ = rpc::MakeChannel(absl::StrCat("127.0.0.1:", server_->port()));
    stub_ = v1::Coordinator::NewStub(channel_);
  }

  // One model as MeshFile in its own ingest stream: the stream's status.
  grpc::Status IngestFile(const MeshCase& file) {
    grpc::ClientContext context;
    rpc::SetDeadline(&context, absl::Seconds(30));
    auto stream = stub_->Ingest(&context);
    v1::IngestRequest request;
    request.set_collection("hostile");
    request.set_model_id(file.name);
    request.mutable_mesh()->mutable_file()->set_name(file.name);
    request.mutable_mesh()->mutable_file()->set_data(file.bytes);
    stream->Write(request);
    stream->WritesDone();
    v1::IngestAck ack;
    while (stream->Read(&ack)) {
    }
    return stream->Finish();
  }

  grpc::Status QueryFile(const MeshCase& file) {
    grpc::ClientContext context;
    rpc::SetDeadline(&context, absl::Seconds(30));
    v1::QueryRequest request;
    request.set_collection("hostile");
    request.set_top_k(3);
    request.mutable_mesh()->mutable_file()->set_name(file.name);
    request.mutable_mesh()->mutable_file()->set_data(file.bytes);
    v1::QueryResponse response;
    return stub_->Query(&context, request, &response);
  }

  std::string dir_;
  std::unique_ptr<ServerProcess> server_;
  std::shared_ptr<grpc::Channel> channel_;
  std::unique_ptr<v1::Coordinator::Stub> stub_;
};

TEST_F(HostileInputTest, BadFilesAreRefusedNamedAndQuicklyValidOnesServedMemoryStaysBounded) {
  {
    grpc::ClientContext context;
    v1::CreateCollectionRequest create;
    create.set_name("hostile");
    create.mutable_params()->set_method(v1::FEATURE_METHOD_DLD);
    create.mutable_params()->set_num_points(64);
    create.mutable_params()->set_vocabulary(8);
    v1::Collection collection;
    ASSERT_TRUE(stub_->CreateCollection(&context, create, &collection).ok());
  }
  // Valid files are ingested (the collection is built from them) ...
  for (const MeshCase& file : ValidFiles()) {
    const grpc::Status status = IngestFile(file);
    EXPECT_TRUE(status.ok()) << file.name << ": " << status.error_message();
  }
  // ... and bad ones refused, naming the file, within a second.
  for (const MeshCase& file : HostileFiles()) {
    const absl::Time start = absl::Now();
    const grpc::Status status = IngestFile(file);
    const absl::Duration took = absl::Now() - start;
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT)
        << file.name << ": " << status.error_message();
    EXPECT_THAT(status.error_message(), HasSubstr(file.name));
    EXPECT_LT(took, absl::Seconds(kSlowdown)) << file.name;
  }
  {
    grpc::ClientContext context;
    v1::BuildRequest build;
    build.set_collection("hostile");
    v1::JobStatus job;
    // Extraction of the valid files may still run: retry while it does.
    grpc::Status started;
    for (int i = 0; i < 600; ++i) {
      grpc::ClientContext attempt;
      started = stub_->Build(&attempt, build, &job);
      if (started.error_code() != grpc::StatusCode::FAILED_PRECONDITION) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    ASSERT_TRUE(started.ok()) << started.error_message();
    v1::JobRequest watch;
    watch.set_job_id(job.job_id());
    auto reader = stub_->WatchJob(&context, watch);
    while (reader->Read(&job)) {
    }
    ASSERT_EQ(job.state(), v1::JOB_STATE_SUCCEEDED) << job.DebugString();
  }
  for (const MeshCase& file : ValidFiles()) {
    const grpc::Status status = QueryFile(file);
    EXPECT_TRUE(status.ok()) << file.name << ": " << status.error_message();
  }
  for (const MeshCase& file : HostileFiles()) {
    const absl::Time start = absl::Now();
    const grpc::Status status = QueryFile(file);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT)
        << file.name << ": " << status.error_message();
    EXPECT_THAT(status.error_message(), HasSubstr(file.name));
    EXPECT_LT(absl::Now() - start, absl::Seconds(kSlowdown)) << file.name;
  }
  // Still serving, and small.
  {
    grpc::ClientContext context;
    v1::GetCollectionRequest get;
    get.set_name("hostile");
    v1::Collection collection;
    ASSERT_TRUE(stub_->GetCollection(&context, get, &collection).ok());
    EXPECT_EQ(collection.models(), ValidFiles().size());
  }
  const double rss = ResidentMiB(server_->pid());
  EXPECT_GT(rss, 0);
  EXPECT_LT(rss, 1024) << "MiB resident after the corpus";
  std::printf("meshseek serve resident after the corpus: %.0f MiB\n", rss);
}

TEST_F(HostileInputTest, TheCliNamesTheBadFileAndNeitherHangsNorBalloons) {
  for (const MeshCase& file : HostileFiles()) {
    const std::string path = dir_ + "/files/" + file.name;
    std::ofstream(path, std::ios::binary) << file.bytes;
    std::string output;
    const absl::Time start = absl::Now();
    const int code = RunCli(absl::StrCat("inspect '", path, "' --out '", dir_, "/inspect'"), &output);
    EXPECT_NE(code, 0) << file.name << ": " << output;
    EXPECT_THAT(output, HasSubstr(file.name));
    EXPECT_LT(absl::Now() - start, absl::Seconds(2 * kSlowdown)) << file.name;
  }
  for (const MeshCase& file : ValidFiles()) {
    const std::string path = dir_ + "/files/" + file.name;
    std::ofstream(path, std::ios::binary) << file.bytes;
    std::string output;
    EXPECT_EQ(RunCli(absl::StrCat("inspect '", path, "' --out '", dir_, "/inspect'"), &output), 0)
        << file.name << ": " << output;
  }
  // The limits are flags: a valid file over one is refused naming it.
  const std::string tetrahedron = dir_ + "/files/tetrahedron.off";
  std::string output;
  EXPECT_NE(RunCli(absl::StrCat("inspect '", tetrahedron, "' --max_mesh_vertices=3 --out '", dir_,
                                "/inspect'"),
                   &output),
            0);
  EXPECT_THAT(output, HasSubstr("max_vertices (3)"));
  EXPECT_NE(RunCli(absl::StrCat("inspect '", tetrahedron, "' --max_mesh_mb=0 --out '", dir_,
                                "/inspect'"),
                   &output),
            0);
  EXPECT_THAT(output, HasSubstr("--max_mesh_mb must be in [1, 1048576], got 0"));
}

}  // namespace
}  // namespace meshseek
