#include "cli/cli_flags.h"

#include "absl/flags/flag.h"
#include "absl/time/time.h"
#include "common/base/status_macros.h"
#include "common/flags/mesh_limit_flags.h"
#include "common/synth/synthetic_benchmark.h"

// The coordinator (cli/coordinator_client.h).
ABSL_FLAG(std::string,
          server,
          "",
          "coordinator address host:port; empty: start the embedded stack on --data_dir; "
          "'in-process': eval without services (the benchmark reference)");
ABSL_FLAG(std::string, data_dir, "meshseek-data", "state folder of the embedded stack");
ABSL_FLAG(std::string,
          tls_ca,
          "",
          "PEM CA bundle the coordinator (--server) is verified against: turns TLS on; "
          "serve: require client certificates signed by it");
ABSL_FLAG(std::string,
          tls_cert,
          "",
          "PEM certificate this process presents: the client's for mutual TLS, or serve's");
ABSL_FLAG(std::string, tls_key, "", "PEM private key of --tls_cert");
ABSL_FLAG(std::string,
          tls_server_name,
          "",
          "name the coordinator's certificate carries, when not the host of --server");
ABSL_FLAG(std::string,
          token_file,
          "",
          "file holding the coordinator's bearer token: sent with every call to --server; "
          "serve: required of every caller");
ABSL_FLAG(absl::Duration,
          reconnect_for,
          absl::Minutes(2),
          "how long the client keeps reconnecting to a coordinator that went away");
ABSL_FLAG(std::string,
          format,
          "text",
          "status, query, eval: 'text' for people, 'json' for programs (one JSON document on "
          "stdout; the proto's field names)");

// The commands.
ABSL_FLAG(std::string,
          collection,
          "",
          "collection name (eval: default <manifest folder>-<method>-<parameter hash>)");
ABSL_FLAG(std::string,
          manifest,
          "",
          "eval: CSV manifest with columns id,class,path (paths relative to it)");
ABSL_FLAG(std::string, folder, "", "ingest: every mesh file in this folder (id = file name)");
ABSL_FLAG(std::string, out, "", "output folder");
ABSL_FLAG(std::string, job, "", "status: a job id to follow until it ends");
ABSL_FLAG(int, top_k, 10, "query: results to print");
ABSL_FLAG(std::string, image, "",
          "query: a picture (PNG or JPEG) of an object to query with instead of a MODEL; the "
          "collection needs lfd (the default fusion has it)");
ABSL_FLAG(int, candidates, 0,
          "query: 0 searches exactly; N re-ranks the N candidates an embedding proposes "
          "(faster on large collections, may miss a neighbour); on a fused collection each "
          "histogram method proposes N and their union is fused and re-ranked (100: recall@10 "
          "0.99 on the development sets)");
ABSL_FLAG(int,
          port,
          -1,
          "serve: coordinator port of the embedded stack (default 50051; 0: any free port); "
          "web: port of the page (default 8080)");
ABSL_FLAG(int,
          metrics_port,
          0,
          "serve: Prometheus metrics of all five services on 127.0.0.1:PORT/metrics; 0: none");
ABSL_FLAG(std::string, eval, "", "report: folder written by `meshseek eval --out`");
ABSL_FLAG(int,
          sample_queries,
          meshseek::EvaluationReportOptions().sample_queries,
          "report: queries shown with their top results (one per class)");
ABSL_FLAG(int,
          top_results,
          meshseek::EvaluationReportOptions().top_results,
          "report: results shown per sampled query");
ABSL_FLAG(int,
          thumbnail_size,
          meshseek::EvaluationReportOptions().thumbnail.size,
          "report: thumbnail size in pixels");
ABSL_FLAG(int,
          models_per_class,
          meshseek::SyntheticBenchmarkOptions().models_per_class,
          "synth: models generated per class");
ABSL_FLAG(int, montage_images, 48, "inspect: depth images in the montage");
ABSL_FLAG(std::string,
          web_host,
          meshseek::cli::WebGatewayOptions().host,
          "web: address the page is served on; beyond loopback (0.0.0.0: every interface) it "
          "needs --web_token_file and --web_tls_cert, or --web_open");
ABSL_FLAG(std::string, web_tls_cert, "", "web: PEM certificate chain of the page's HTTPS");
ABSL_FLAG(std::string, web_tls_key, "", "web: PEM private key of --web_tls_cert");
ABSL_FLAG(std::string,
          web_token_file,
          "",
          "web: file holding the bearer token every API call of the page must carry "
          "(the coordinator's --token_file may serve)");
ABSL_FLAG(bool,
          web_open,
          false,
          "web: serve a non-loopback --web_host without token and TLS (a private network, or "
          "behind a proxy that authenticates)");
ABSL_FLAG(int, web_upload_mb, 64, "web: largest mesh file a browser may upload, in MiB");

namespace meshseek::cli {

absl::StatusOr<CliFlags> ReadCliFlags(const flags::ParamFlags& params) {
  CliFlags f;
  f.params = params;
  f.client.server = absl::GetFlag(FLAGS_server);
  f.client.data_dir = absl::GetFlag(FLAGS_data_dir);
  f.client.security.tls.ca_file = absl::GetFlag(FLAGS_tls_ca);
  f.client.security.tls.cert_file = absl::GetFlag(FLAGS_tls_cert);
  f.client.security.tls.key_file = absl::GetFlag(FLAGS_tls_key);
  f.client.security.server_name = absl::GetFlag(FLAGS_tls_server_name);
  f.client.security.token_file = absl::GetFlag(FLAGS_token_file);
  f.client.reconnect_for = absl::GetFlag(FLAGS_reconnect_for);
  f.client.threads = params.threads;
  f.client.progress = params.progress;
  MESHSEEK_ASSIGN_OR_RETURN(f.client.mesh_limits, flags::MeshLimitsFromFlags());
  MESHSEEK_ASSIGN_OR_RETURN(f.format, OutputFormatFromName(absl::GetFlag(FLAGS_format)));

  f.collection = absl::GetFlag(FLAGS_collection);
  f.manifest = absl::GetFlag(FLAGS_manifest);
  f.folder = absl::GetFlag(FLAGS_folder);
  f.out = absl::GetFlag(FLAGS_out);
  f.job = absl::GetFlag(FLAGS_job);
  f.top_k = absl::GetFlag(FLAGS_top_k);
  f.candidates = absl::GetFlag(FLAGS_candidates);
  f.image = absl::GetFlag(FLAGS_image);
  f.port = absl::GetFlag(FLAGS_port);
  f.metrics_port = absl::GetFlag(FLAGS_metrics_port);

  f.eval_dir = absl::GetFlag(FLAGS_eval);
  f.report.sample_queries = absl::GetFlag(FLAGS_sample_queries);
  f.report.top_results = absl::GetFlag(FLAGS_top_results);
  f.report.thumbnail.size = absl::GetFlag(FLAGS_thumbnail_size);
  f.report.num_threads = params.threads;
  f.models_per_class = absl::GetFlag(FLAGS_models_per_class);
  f.montage_images = absl::GetFlag(FLAGS_montage_images);
  f.web.host = absl::GetFlag(FLAGS_web_host);
  f.web.tls.cert_file = absl::GetFlag(FLAGS_web_tls_cert);
  f.web.tls.key_file = absl::GetFlag(FLAGS_web_tls_key);
  f.web.token_file = absl::GetFlag(FLAGS_web_token_file);
  f.web.open = absl::GetFlag(FLAGS_web_open);
  f.web.max_upload_bytes = static_cast<std::size_t>(absl::GetFlag(FLAGS_web_upload_mb)) << 20;
  return f;
}

}  // namespace meshseek::cli
