// meshseek-probe: a tiny gRPC health probe for containers (Docker
// HEALTHCHECK, Kubernetes exec probes on old clusters). Calls
// grpc.health.v1.Health/Check and exits 0 when the server is SERVING, 1
// otherwise, printing the status. With --list it prints the services the
// server offers through reflection instead (what `grpcurl list` shows).
//
//   meshseek-probe --addr localhost:50051 [--service name] [--timeout 2s]
//   meshseek-probe --addr localhost:50051 --list
//   meshseek-probe --addr extract:50051 --tls_ca ca.pem [--tls_cert c.pem --tls_key c.key]
// With TLS flags it connects as every meshseek client does (common/rpc/credentials.h).
#include <iostream>

#include "absl/flags/flag.h"
#include "absl/flags/parse.h"
#include "absl/flags/usage.h"
#include "absl/time/time.h"
#include <grpcpp/grpcpp.h>

#include "common/rpc/credentials.h"
#include "grpc/health/v1/health.grpc.pb.h"
#include "grpc/reflection/v1alpha/reflection.grpc.pb.h"

ABSL_FLAG(std::string, addr, "localhost:50051", "server to check, host:port");
ABSL_FLAG(std::string, service, "", "service name to check (empty: the whole server)");
ABSL_FLAG(absl::Duration, timeout, absl::Seconds(2), "deadline of the check");
ABSL_FLAG(bool, list, false, "list the server's services through reflection");
ABSL_FLAG(std::string, tls_ca, "", "PEM CA bundle the server is verified against (turns TLS on)");
ABSL_FLAG(std::string, tls_cert, "", "PEM client certificate, for servers that require one");
ABSL_FLAG(std::string, tls_key, "", "PEM private key of --tls_cert");
ABSL_FLAG(std::string, tls_server_name, "",
          "name the server's certificate carries, when not the host of --addr");

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
  meshseek::rpc::ClientSecurityOptions security;
  security.tls.ca_file = absl::GetFlag(FLAGS_tls_ca);
  security.tls.cert_file = absl::GetFlag(FLAGS_tls_cert);
  security.tls.key_file = absl::GetFlag(FLAGS_tls_key);
  security.server_name = absl::GetFlag(FLAGS_tls_server_name);
  auto credentials = meshseek::rpc::MakeChannelCredentials(security);
  if (!credentials.ok()) {
    std::cout << "bad flags: " << credentials.status().message() << "\n";
    return 2;
  }
  grpc::ChannelArguments args;
  if (!security.server_name.empty()) args.SetSslTargetNameOverride(security.server_name);
  auto channel = grpc::CreateCustomChannel(absl::GetFlag(FLAGS_addr), *credentials, args);
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
