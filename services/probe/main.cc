// meshseek-probe: a tiny gRPC health probe for containers (Docker
// HEALTHCHECK, Kubernetes exec probes on old clusters). Calls
// grpc.health.v1.Health/Check and exits 0 when the server is SERVING, 1
// otherwise, printing the status. With --list it prints the services the
// server offers through reflection instead (what `grpcurl list` shows).
//
//   meshseek-probe --addr localhost:50051 [--service name] [--timeout 2s]
//   meshseek-probe --addr localhost:50051 --list
#include <iostream>

#include "absl/flags/flag.h"
#include "absl/flags/parse.h"
#include "absl/flags/usage.h"
#include "absl/time/time.h"
#include <grpcpp/grpcpp.h>

#include "grpc/health/v1/health.grpc.pb.h"
#include "grpc/reflection/v1alpha/reflection.grpc.pb.h"

ABSL_FLAG(std::string, addr, "localhost:50051", "server to check, host:port");
ABSL_FLAG(std::string, service, "", "service name to check (empty: the whole server)");
ABSL_FLAG(absl::Duration, timeout, absl::Seconds(2), "deadline of the check");
ABSL_FLAG(bool, list, false, "list the server's services through reflection");

namespace {

int ListServices(const std::shared_ptr<grpc::Channel>& channel, grpc::ClientContext* context) {
  auto stub = grpc::reflection::v1alpha::ServerReflection::NewStub(channel);
  auto stream = stub->ServerReflectionInfo(context);
  grpc::reflection::v1alpha::ServerReflectionRequest request;
  request.set_list_services("");
  stream->Write(request);
  stream->WritesDone();
  grpc::reflection::v1alpha::ServerReflectionResponse response;
  const bool got = stream->Read(&response);
  const grpc::Status status = stream->Finish();
  if (!got || !status.ok()) {
    std::cout << "reflection failed: " << status.error_message() << "\n";
    return 1;
  }
  for (const auto& service : response.list_services_response().service()) {
    std::cout << service.name() << "\n";
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  absl::SetProgramUsageMessage("exits 0 when the gRPC server at --addr is SERVING");
  absl::ParseCommandLine(argc, argv);
  auto channel = grpc::CreateChannel(absl::GetFlag(FLAGS_addr), grpc::InsecureChannelCredentials());
  auto stub = grpc::health::v1::Health::NewStub(channel);
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() +
                       absl::ToChronoMilliseconds(absl::GetFlag(FLAGS_timeout)));
  if (absl::GetFlag(FLAGS_list)) return ListServices(channel, &context);
  grpc::health::v1::HealthCheckRequest request;
  request.set_service(absl::GetFlag(FLAGS_service));
  grpc::health::v1::HealthCheckResponse response;
  const grpc::Status status = stub->Check(&context, request, &response);
  if (!status.ok()) {
    std::cout << "unhealthy: " << status.error_message() << "\n";
    return 1;
  }
  std::cout << grpc::health::v1::HealthCheckResponse::ServingStatus_Name(response.status())
            << "\n";
  return response.status() == grpc::health::v1::HealthCheckResponse::SERVING ? 0 : 1;
}
