// Query by picture through the embedded services (docs/design.md 2.7d): a
// collection with LFD answers a picture of one of its models with a model of
// that class first; one without LFD answers FAILED_PRECONDITION naming what
// it would need; hostile pictures are refused by name and the server keeps
// serving.
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/time/clock.h"
#include "common/global/lfd_cameras.h"
#include "common/render/png.h"
#include "common/render/view_renderer.h"
#include "common/rpc/client.h"
#include "common/synth/synthetic_benchmark.h"
#include "common/wire/convert.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "meshseek/v1/coordinator.grpc.pb.h"
#include "services/embedded/embedded_stack.h"

namespace meshseek {
namespace {

using ::testing::HasSubstr;

class PictureQueryTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new std::string(::testing::TempDir() + "/meshseek_picture_query");
    std::filesystem::remove_all(*dir_);
    auto stack = EmbeddedStack::Start(*dir_, 2);
    ASSERT_TRUE(stack.ok()) << stack.status();
    stack_ = stack->release();
    stub_ = v1::Coordinator::NewStub(rpc::MakeChannel(stack_->coordinator_address())).release();
    SyntheticBenchmarkOptions synth;
    synth.models_per_class = 3;
    synth.classes = {"snake", "spider", "table"};
    auto models = MakeSyntheticModels(synth);
    ASSERT_TRUE(models.ok()) << models.status();
    models_ = new std::vector<SyntheticModel>(*std::move(models));
    // One collection with LFD, one without.
    using Params = std::vector<std::pair<std::string, std::string>>;
    const std::pair<std::string, Params> collections[] = {
        {"views", {{"method", "lfd"}}},
        {"histograms", {{"method", "dld"}, {"points", "64"}, {"vocabulary", "8"}}}};
    for (const auto& [name, params] : collections) {
      grpc::ClientContext context;
      v1::CreateCollectionRequest request;
      request.set_name(name);
      for (const auto& [param, value] : params) {
        v1::ParamValue* v = request.mutable_params()->add_values();
        v->set_name(param);
        v->set_value(value);
      }
      v1::Collection response;
      const grpc::Status status = stub_->CreateCollection(&context, request, &response);
      ASSERT_TRUE(status.ok()) << status.error_message();
      IngestAndBuild(name);
    }
  }
  static void TearDownTestSuite() {
    delete stub_;
    delete stack_;
    delete models_;
    std::filesystem::remove_all(*dir_);
    delete dir_;
  }

  static void IngestAndBuild(const std::string& collection) {
    {
      grpc::ClientContext context;
      auto stream = stub_->Ingest(&context);
      for (const SyntheticModel& model : *models_) {
        v1::IngestRequest request;
        request.set_collection(collection);
        request.set_model_id(model.id);
        request.set_label(model.label);
        wire::MeshToProto(model.mesh, request.mutable_mesh()->mutable_mesh());
        ASSERT_TRUE(stream->Write(request));
        v1::IngestAck ack;
        ASSERT_TRUE(stream->Read(&ack));
      }
      stream->WritesDone();
      const grpc::Status status = stream->Finish();
      ASSERT_TRUE(status.ok()) << status.error_message();
    }
    // A build needs every model extracted.
    v1::Collection state;
    for (absl::Time give_up = absl::Now() + absl::Seconds(120); absl::Now() < give_up;) {
      grpc::ClientContext context;
      v1::GetCollectionRequest request;
      request.set_name(collection);
      ASSERT_TRUE(stub_->GetCollection(&context, request, &state).ok());
      if (state.pending() == 0) break;
      absl::SleepFor(absl::Milliseconds(100));
    }
    ASSERT_EQ(state.pending(), 0u);
    v1::JobStatus job;
    {
      grpc::ClientContext context;
      v1::BuildRequest request;
      request.set_collection(collection);
      const grpc::Status status = stub_->Build(&context, request, &job);
      ASSERT_TRUE(status.ok()) << status.error_message();
    }
    for (absl::Time give_up = absl::Now() + absl::Seconds(120);
         job.state() == v1::JOB_STATE_RUNNING && absl::Now() < give_up;) {
      absl::SleepFor(absl::Milliseconds(100));
      grpc::ClientContext context;
      v1::JobRequest request;
      request.set_job_id(job.job_id());
      ASSERT_TRUE(stub_->GetJob(&context, request, &job).ok());
    }
    ASSERT_EQ(job.state(), v1::JOB_STATE_SUCCEEDED) << job.message();
  }

  // A picture of `mesh` from a direction no light field uses: black object
  // on white, 200 x 200 pixels.
  static std::string PictureOf(const TriangleMesh& mesh) {
    ViewRenderOptions options;
    options.image_size = 200;
    options.window_scale = 1.2;
    const ViewImage view = ViewRenderer::Create(mesh, options)->Render(Normalized({0.3, 0.8, 0.52}));
    cv::Mat picture(view.size, view.size, CV_8UC1);
    for (int i = 0; i < view.size * view.size; ++i) picture.data[i] = view.mask[i] ? 0 : 255;
    return *EncodePng(picture);
  }

  static Vec3d Normalized(const Vec3d& v) {
    return v * (1 / std::sqrt(v.x * v.x + v.y * v.y + v.z * v.z));
  }

  static grpc::Status QueryByImage(const std::string& collection,
                                   const std::string& image,
                                   v1::QueryResponse* response,
                                   uint32_t top_k = 3) {
    grpc::ClientContext context;
    v1::QueryByImageRequest request;
    request.set_collection(collection);
    request.set_image(image);
    request.set_top_k(top_k);
    return stub_->QueryByImage(&context, request, response);
  }

  static std::string* dir_;
  static EmbeddedStack* stack_;
  static v1::Coordinator::Stub* stub_;
  static std::vector<SyntheticModel>* models_;
};

std::string* PictureQueryTest::dir_ = nullptr;
EmbeddedStack* PictureQueryTest::stack_ = nullptr;
v1::Coordinator::Stub* PictureQueryTest::stub_ = nullptr;
std::vector<SyntheticModel>* PictureQueryTest::models_ = nullptr;

TEST_F(PictureQueryTest, APictureOfAModelFindsItsClassFirst) {
  for (const std::size_t i : {0u, 4u, 8u}) {
    const SyntheticModel& model = (*models_)[i];
    v1::QueryResponse response;
    const grpc::Status status = QueryByImage("views", PictureOf(model.mesh), &response);
    ASSERT_TRUE(status.ok()) << status.error_message();
    ASSERT_EQ(response.results_size(), 3);
    EXPECT_EQ(response.results(0).label(), model.label) << "model " << model.id;
    EXPECT_LE(response.results(0).distance(), response.results(1).distance());
    EXPECT_GT(response.timings().search_seconds(), 0);
  }
}

TEST_F(PictureQueryTest, ACollectionWithoutViewsSaysWhatItWouldNeed) {
  v1::QueryResponse response;
  const grpc::Status status =
      QueryByImage("histograms", PictureOf((*models_)[0].mesh), &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::FAILED_PRECONDITION);
  EXPECT_THAT(status.error_message(), HasSubstr("(dld)"));
  EXPECT_THAT(status.error_message(), HasSubstr("it needs lfd"));
  EXPECT_EQ(QueryByImage("nowhere", PictureOf((*models_)[0].mesh), &response).error_code(),
            grpc::StatusCode::NOT_FOUND);
  EXPECT_EQ(QueryByImage("views", PictureOf((*models_)[0].mesh), &response, 0).error_code(),
            grpc::StatusCode::INVALID_ARGUMENT);
}

// CRC-32 (PNG's chunk checksum), bit by bit.
uint32_t Crc32(const std::string& bytes) {
  uint32_t crc = 0xFFFFFFFFu;
  for (const char c : bytes) {
    crc ^= static_cast<uint8_t>(c);
    for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
  }
  return ~crc;
}

TEST_F(PictureQueryTest, HostilePicturesAreRefusedByNameAndTheServerKeepsServing) {
  const std::string good = PictureOf((*models_)[3].mesh);
  // A PNG whose header declares 100,000 x 100,000 pixels (IHDR's width and
  // height at bytes 16 to 23, its CRC after them), refused from the header.
  std::string huge = *EncodePng(cv::Mat(16, 16, CV_8UC1, cv::Scalar(255)));
  for (const int at : {16, 20}) huge.replace(at, 4, std::string("\x00\x01\x86\xA0", 4));
  const uint32_t crc = Crc32(huge.substr(12, 17));
  for (int k = 0; k < 4; ++k) huge[29 + k] = static_cast<char>(crc >> (24 - 8 * k));
  const std::pair<std::string, std::string> hostile[] = {
      {"", "neither PNG nor JPEG"},
      {"not a picture at all", "neither PNG nor JPEG"},
      {good.substr(0, good.size() / 2), "PNG"},
      {*EncodePng(cv::Mat(1, 1, CV_8UC3, cv::Scalar(1, 2, 3))), "no object stands out"},
      {*EncodePng(cv::Mat(64, 64, CV_8UC1, cv::Scalar(128))), "no object stands out"},
      {huge, "100000 x 100000"},
  };
  for (const auto& [bytes, says] : hostile) {
    v1::QueryResponse response;
    const grpc::Status status = QueryByImage("views", bytes, &response);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << says;
    EXPECT_THAT(status.error_message(), HasSubstr(says));
    EXPECT_THAT(status.error_message(), HasSubstr("query by picture"));
  }
  v1::QueryResponse response;
  const grpc::Status status = QueryByImage("views", good, &response);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_EQ(response.results_size(), 3);
}

}  // namespace
}  // namespace meshseek
