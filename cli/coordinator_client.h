// The coordinator a client command talks to, and what the commands do with
// it: --server HOST:PORT (with TLS and a bearer token when the options give
// them), or an embedded stack of every service started on a data folder for
// the client's lifetime. Unary calls are retried while the coordinator is
// unreachable (idempotent calls only); the ingest stream reconnects and sends
// again what was not acknowledged; jobs are followed across coordinator
// restarts (they are durable). Used by the client commands, eval through the
// services and the web gateway; it reads no flag (cli_flags.h does).
#ifndef MESHSEEK_CLI_COORDINATOR_CLIENT_H_
#define MESHSEEK_CLI_COORDINATOR_CLIENT_H_

#include <memory>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/time/time.h"
#include "common/eval/manifest.h"
#include "common/flags/pipeline_flags.h"
#include "common/geometry/mesh_io.h"
#include "common/rpc/client.h"
#include "common/rpc/credentials.h"
#include "meshseek/v1/coordinator.grpc.pb.h"
#include "services/embedded/embedded_stack.h"

namespace meshseek::cli {

struct ClientOptions {
  /// host:port of the coordinator; empty: an embedded stack on data_dir.
  std::string server;
  std::string data_dir = "meshseek-data";
  /// TLS and token towards `server` (the embedded stack listens on loopback
  /// in plaintext).
  rpc::ClientSecurityOptions security;
  /// How long calls, the ingest stream and job watches keep reconnecting to
  /// a coordinator that went away.
  absl::Duration reconnect_for = absl::Minutes(2);
  /// The embedded stack's extraction slots (<= 0: cores).
  int threads = 0;
  /// Progress bars on stderr while ingesting and following jobs.
  bool progress = true;
  /// The meshes read from files and the embedded stack accepts.
  MeshReadOptions mesh_limits;
};

/// A model file to send: its id, label, path, and where it comes from for
/// error messages ("model 'b' (manifest line 3)").
struct ModelToIngest {
  std::string id;
  std::string label;
  std::string path;
  std::string where;
};

/// The models of a manifest, each named by its id and line.
std::vector<ModelToIngest> ModelsOfManifest(const std::vector<ManifestEntry>& entries);

class CoordinatorClient {
 public:
  /// Connects to options.server, or starts the embedded stack when it is empty.
  static absl::StatusOr<std::unique_ptr<CoordinatorClient>> Open(const ClientOptions& options);

  v1::Coordinator::Stub* stub() { return stub_.get(); }
  /// Retries while the coordinator is unreachable, for reconnect_for.
  const rpc::RetryOptions& retry() const { return retry_; }

  /// A unary call with a deadline, retried while the coordinator is
  /// unreachable (only for idempotent calls).
  template <typename Request, typename Response, typename Method>
  absl::Status Call(Method method,
                    const Request& request,
                    Response* response,
                    absl::Duration deadline = absl::Minutes(1)) {
    return rpc::CallWithRetry(stub_.get(), method, request, response, deadline, retry_);
  }

  /// Follows a job until it ends, drawing its progress under `label`;
  /// FailedPrecondition with the job's errors when it failed.
  absl::StatusOr<v1::JobStatus> WaitForJob(const std::string& job_id, const std::string& label);

  /// Streams every model into `collection` (each file read within the mesh
  /// limits), reconnecting and sending again what was not acknowledged if
  /// the stream breaks, then waits for the extraction jobs.
  absl::Status Ingest(const std::string& collection, const std::vector<ModelToIngest>& models);

  /// Creates `name` with the parameters of `params` unless it exists; a
  /// collection that exists keeps its own, and parameter flags that disagree
  /// with them are an error (flags::CheckFlagsAgreeWith).
  absl::Status EnsureCollection(const std::string& name, const flags::ParamFlags& params);

  /// Starts a build of `name` and follows it to its end.
  absl::Status Build(const std::string& name);

  absl::StatusOr<v1::Collection> GetCollection(const std::string& name);
  /// Every collection clients created, by name.
  absl::StatusOr<std::vector<v1::Collection>> ListCollections();
  /// Every failed model of `collection` and why, a page at a time.
  absl::StatusOr<std::vector<v1::ModelInfo>> FailedModels(const std::string& collection);

 private:
  ClientOptions options_;
  rpc::RetryOptions retry_;
  std::unique_ptr<EmbeddedStack> stack_;
  std::unique_ptr<v1::Coordinator::Stub> stub_;
};

}  // namespace meshseek::cli

#endif  // MESHSEEK_CLI_COORDINATOR_CLIENT_H_
