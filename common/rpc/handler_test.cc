// The RPC edge (handler.h): a handler's absl::Status reaches the client as the
// grpc::Status of the same code and message, its response only when OK; an
// in-process call (no context) has no deadline and is never cancelled.
#include "common/rpc/handler.h"

#include "gtest/gtest.h"
#include "meshseek/v1/index.grpc.pb.h"

namespace meshseek::rpc {
namespace {

class FakeIndex {
 public:
  absl::StatusOr<v1::AddModelResponse> AddModel(const v1::AddModelRequest& request,
                                                const CallContext& call) {
    deadline = call.deadline();
    if (request.model_id().empty()) return absl::InvalidArgumentError("add: model_id is empty");
    v1::AddModelResponse response;
    response.set_collection_size(7);
    return response;
  }
  absl::Time deadline;
};

TEST(HandlerTest, ResponseOnlyWhenOk) {
  FakeIndex index;
  grpc::ServerContext context;
  v1::AddModelRequest request;
  request.set_model_id("m1");
  v1::AddModelResponse response;
  const grpc::Status ok = Serve(&context, &request, &response, &index, &FakeIndex::AddModel);
  EXPECT_TRUE(ok.ok());
  EXPECT_EQ(response.collection_size(), 7u);

  request.clear_model_id();
  v1::AddModelResponse untouched;
  const grpc::Status refused = Serve(&context, &request, &untouched, &index, &FakeIndex::AddModel);
  EXPECT_EQ(refused.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_EQ(refused.error_message(), "add: model_id is empty");
  EXPECT_EQ(untouched.collection_size(), 0u);
}

TEST(HandlerTest, InProcessCallHasNoDeadline) {
  const CallContext in_process(nullptr);
  EXPECT_EQ(in_process.deadline(), absl::InfiniteFuture());
  EXPECT_FALSE(in_process.cancelled());
}

}  // namespace
}  // namespace meshseek::rpc
