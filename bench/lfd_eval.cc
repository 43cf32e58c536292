// Light Field Descriptor retrieval on a manifest: every model extracted in
// parallel, the all-pairs distance matrix, the retrieval metrics and the
// timings.
//
//   lfd_eval --manifest FILE [--threads=2] [--image_size=I] [--contour_samples=S]
//            [--zernike_radius=view|lightfield] [--distances_out=FILE] [--descriptors_out=FILE]
//
// Labels are the manifest's `class` column (as `meshseek eval` and
// bench/rank_check take them). Prints the metrics table (FormatMetricsTable,
// leave-one-out, DESIGN.md 3.2) and: mesh reading time, per-model extraction
// median and 90th percentile (thread CPU time: one model stays on one core),
// extraction wall time on all threads, all-pairs wall and CPU time (on a
// shared machine the CPU times are the steadier figures).
// --distances_out writes the N x N float32 matrix (tools/psb_eval.py reads
// it); --descriptors_out writes the N descriptors, kLfdDescriptorBytes each,
// in manifest order.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <string>
#include <vector>

#include "absl/flags/flag.h"
#include "absl/flags/parse.h"
#include "common/base/parallel.h"
#include "common/eval/distance_matrix.h"
#include "common/eval/manifest.h"
#include "common/eval/retrieval_metrics.h"
#include "common/geometry/mesh_io.h"
#include "common/global/lfd.h"

ABSL_FLAG(std::string, manifest, "", "CSV manifest id,class,path");
ABSL_FLAG(int, threads, 2, "threads for extraction and the all-pairs matrix (<= 0: all cores)");
ABSL_FLAG(int, image_size, meshseek::LfdOptions().image_size, "silhouette side in pixels");
ABSL_FLAG(int,
          contour_samples,
          meshseek::LfdOptions().contour_samples,
          "contour points for the Fourier descriptor");
ABSL_FLAG(std::string,
          zernike_radius,
          "view",
          "Zernike disc radius: view (each silhouette's own) or lightfield (shared by a light "
          "field's 10 views, the original's)");
ABSL_FLAG(std::string, distances_out, "", "write the N x N float32 distance matrix here");
ABSL_FLAG(std::string, descriptors_out, "", "write the N descriptors here (raw bytes)");

namespace meshseek {
namespace {

double Since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// CPU time of the whole process (all threads).
double ProcessCpuSeconds() {
  timespec t;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return t.tv_sec + t.tv_nsec * 1e-9;
}

double ThreadCpuSeconds() {
  timespec t;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return t.tv_sec + t.tv_nsec * 1e-9;
}

int Run() {
  const std::string manifest = absl::GetFlag(FLAGS_manifest);
  auto models = ReadManifest(manifest);
  if (!models.ok()) {
    std::fprintf(stderr, "%s\n", models.status().ToString().c_str());
    return 2;
  }
  LfdOptions options;
  options.image_size = absl::GetFlag(FLAGS_image_size);
  options.contour_samples = absl::GetFlag(FLAGS_contour_samples);
  const std::string radius = absl::GetFlag(FLAGS_zernike_radius);
  if (radius != "view" && radius != "lightfield") {
    std::fprintf(stderr, "--zernike_radius must be view or lightfield, got %s\n", radius.c_str());
    return 2;
  }
  options.zernike_radius =
      radius == "view" ? LfdZernikeRadius::kPerView : LfdZernikeRadius::kPerLightField;
  if (absl::Status s = options.Validate(); !s.ok()) {
    std::fprintf(stderr, "%s\n", s.ToString().c_str());
    return 2;
  }
  const int threads = ResolveThreadCount(absl::GetFlag(FLAGS_threads));
  const std::size_t n = models->size();

  auto start = std::chrono::steady_clock::now();
  std::vector<TriangleMesh> meshes(n);
  std::vector<absl::Status> errors(n);
  ParallelFor(n, threads, [&](std::size_t i) {
    auto mesh = ReadMesh((*models)[i].path);
    if (mesh.ok()) {
      meshes[i] = *std::move(mesh);
    } else {
      errors[i] = mesh.status();
    }
  });
  const double read_s = Since(start);

  start = std::chrono::steady_clock::now();
  std::vector<std::vector<uint8_t>> descriptors(n);
  std::vector<double> cpu_s(n, 0.0);
  ParallelFor(n, threads, [&](std::size_t i) {
    if (!errors[i].ok()) return;
    const double t0 = ThreadCpuSeconds();
    auto d = ExtractLfd(meshes[i], options);
    cpu_s[i] = ThreadCpuSeconds() - t0;
    if (d.ok()) {
      descriptors[i] = *std::move(d);
    } else {
      errors[i] = d.status();
    }
    meshes[i] = TriangleMesh();  // free as we go
  });
  const double extract_s = Since(start);
  for (std::size_t i = 0; i < n; ++i) {
    if (!errors[i].ok()) {
      const ManifestEntry& m = (*models)[i];
      std::fprintf(stderr,
                   "%s:%d: model %s (%s): %s\n",
                   manifest.c_str(),
                   m.line,
                   m.id.c_str(),
                   m.path.c_str(),
                   errors[i].ToString().c_str());
      return 1;
    }
  }

  start = std::chrono::steady_clock::now();
  const double matrix_cpu0 = ProcessCpuSeconds();
  auto matrix = LfdDistanceMatrix(descriptors, threads);
  const double matrix_s = Since(start);
  const double matrix_cpu_s = ProcessCpuSeconds() - matrix_cpu0;
  if (!matrix.ok()) {
    std::fprintf(stderr, "%s\n", matrix.status().ToString().c_str());
    return 1;
  }
  std::vector<std::string> labels;
  for (const ManifestEntry& m : *models) labels.push_back(m.label);
  auto metrics = EvaluateRetrieval(labels, *matrix, threads);
  if (!metrics.ok()) {
    std::fprintf(stderr, "%s\n", metrics.status().ToString().c_str());
    return 1;
  }
  if (const std::string out = absl::GetFlag(FLAGS_distances_out); !out.empty()) {
    if (absl::Status s = WriteDistanceMatrix(out, *matrix, n); !s.ok()) {
      std::fprintf(stderr, "%s\n", s.ToString().c_str());
      return 1;
    }
  }
  if (const std::string out = absl::GetFlag(FLAGS_descriptors_out); !out.empty()) {
    std::FILE* f = std::fopen(out.c_str(), "wb");
    bool ok = f != nullptr;
    for (const auto& d : descriptors) ok = ok && std::fwrite(d.data(), 1, d.size(), f) == d.size();
    if (f != nullptr) ok = std::fclose(f) == 0 && ok;
    if (!ok) {
      std::fprintf(stderr, "%s: cannot write the descriptors\n", out.c_str());
      return 1;
    }
  }

  std::vector<double> sorted = cpu_s;
  std::sort(sorted.begin(), sorted.end());
  double total_cpu = 0;
  for (double s : cpu_s) total_cpu += s;
  std::printf(
      "%s: %zu models, LFD image_size %d, contour_samples %d, zernike_radius %s, %d threads, "
      "SIMD %s\n",
      manifest.c_str(),
      n,
      options.image_size,
      options.contour_samples,
      radius.c_str(),
      threads,
      SimdLevelName(DetectedSimdLevel()));
  std::printf("%s", FormatMetricsTable(*metrics).c_str());
  std::printf(
      "timings: read meshes %.1f s; extraction per model (one core, thread CPU) median %.0f ms, "
      "p90 %.0f ms, max %.0f ms, total %.1f CPU s, %.1f s wall on %d threads; "
      "all-pairs %zu x %zu (%zu distances) %.2f s wall on %d threads, %.2f CPU s "
      "(%.1f us CPU per distance)\n",
      read_s,
      1e3 * sorted[n / 2],
      1e3 * sorted[n * 9 / 10],
      1e3 * sorted.back(),
      total_cpu,
      extract_s,
      threads,
      n,
      n,
      n * (n - 1) / 2,
      matrix_s,
      threads,
      matrix_cpu_s,
      1e6 * matrix_cpu_s / std::max<std::size_t>(1, n * (n - 1) / 2));
  return 0;
}

}  // namespace
}  // namespace meshseek

int main(int argc, char** argv) {
  absl::ParseCommandLine(argc, argv);
  return meshseek::Run();
}
