// meshseek-probe: a tiny gRPC health probe for containers (Docker
// HEALTHCHECK, Kubernetes exec probes on old clusters). Calls
// grpc.health.v1.Health/Check and exits 0 when the server is SERVING, 1
// otherwise, printing the status.
//
//   meshseek-probe --addr localhost:50051 [--service name] [--timeout 2s]
#include <iostream>

#include "absl/flags/flag.h"
#include "absl/flags/parse.h"
#include "absl/flags/usage.h"
#include "absl/time/time.h"
#include "common/rpc/client.h"
#include "grpc/health/v1/health.grpc.pb.h"

ABSL_FLAG(std::string, addr, "localhost:50051", "server to check, host:port");
ABSL_FLAG(std::string, service, "", "service name to check (empty: the whole server)");
ABSL_FLAG(absl::Duration, timeout, absl::Seconds(2), "deadline of the check");

int main(int argc, char** argv) {
  absl::SetProgramUsageMessage("exits 0 when the gRPC server at --addr is SERVING");
  absl::ParseCommandLine(argc, argv);
  auto channel = grpc::CreateChannel(absl::GetFlag(FLAGS_addr), grpc::InsecureChannelCredentials());
  auto stub = grpc::health::v1::Health::NewStub(channel);
  grpc::ClientContext context;
  meshseek::rpc::SetDeadline(&context, absl::GetFlag(FLAGS_timeout));
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
