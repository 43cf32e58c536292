// The embedded default: every meshseek service in this process, each a real
// gRPC server on a loopback port, with state under one data folder
// (DATA/codebook, DATA/index, DATA/coordinator). The CLI starts it when no
// --server is given, talks to it over gRPC exactly as to a cluster, and stops
// it at exit; state persists between runs. `meshseek serve` keeps it running.
#ifndef MESHSEEK_SERVICES_EMBEDDED_EMBEDDED_STACK_H_
#define MESHSEEK_SERVICES_EMBEDDED_EMBEDDED_STACK_H_

#include <memory>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "common/rpc/server.h"
#include "services/codebook/codebook_service.h"
#include "services/coordinator/coordinator_service.h"
#include "services/extract/extract_service.h"
#include "services/index/index_service.h"
#include "services/resample/resample_service.h"

namespace meshseek {

struct EmbeddedSecurity {
  /// TLS, client certificates and bearer token of the coordinator's port
  /// (`meshseek serve --tls_cert ... --token_file ...`). Default: plaintext.
  rpc::ServerSecurityOptions coordinator;
  /// Mutual TLS among the services: each serves with cert_file/key_file and
  /// requires client certificates signed by ca_file, and the coordinator
  /// presents the same certificate to them (it must name 127.0.0.1). Off
  /// when empty: the inner services listen on loopback only.
  rpc::TlsOptions internal;
};

class EmbeddedStack {
 public:
  /// Starts the five services; the coordinator listens on `coordinator_port`
  /// (0: any free port) on 127.0.0.1, the others on free loopback ports.
  /// `threads`: extraction slots and coordinator in-flight models (<= 0: cores).
  /// `mesh_limits` bound the meshes the services accept. `metrics_port`: the
  /// one Prometheus endpoint of all five services on 127.0.0.1 (their calls
  /// are labelled by service); 0: none.
  static absl::StatusOr<std::unique_ptr<EmbeddedStack>> Start(
      const std::string& data_dir,
      int threads,
      int coordinator_port = 0,
      const EmbeddedSecurity& security = {},
      const MeshReadOptions& mesh_limits = {},
      int metrics_port = 0);
  ~EmbeddedStack();

  /// "127.0.0.1:PORT" of the coordinator.
  const std::string& coordinator_address() const { return coordinator_address_; }

 private:
  EmbeddedStack() = default;
  std::unique_ptr<ResampleService> resample_;
  std::unique_ptr<ExtractService> extract_;
  std::unique_ptr<CodebookService> codebook_;
  std::unique_ptr<IndexService> index_;
  std::unique_ptr<CoordinatorService> coordinator_;
  // Each service's gRPC entry points (services/*/*_grpc.h); outlive the servers.
  std::vector<std::unique_ptr<grpc::Service>> bindings_;
  std::vector<std::unique_ptr<rpc::RpcServer>> servers_;  // coordinator last
  std::string coordinator_address_;
};

}  // namespace meshseek

#endif  // MESHSEEK_SERVICES_EMBEDDED_EMBEDDED_STACK_H_
