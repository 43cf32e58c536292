#include "common/features/rld_sift.h"


#include "absl/strings/str_cat.h"
#include "common/base/status_macros.h"
#include "common/features/local_depth_sift.h"
#include "common/geometry/point_graph.h"

namespace meshseek {

absl::Status RldSiftOptions::Validate() const {
  if (num_samples < 100 || num_samples > 10000000) {
    return absl::InvalidArgumentError(
        absl::StrCat("RLD-SIFT num_samples must be in [100, 10000000], got ", num_samples));
  }
  if (neighbors < 1 || neighbors > 100) {
    return absl::InvalidArgumentError(
        absl::StrCat("RLD-SIFT neighbors k must be in [1, 100], got ", neighbors));
  }
  MESHSEEK_RETURN_IF_ERROR(scale_space.Validate());
  MESHSEEK_RETURN_IF_ERROR(depth_image.Validate());
  return descriptor.Validate();
}

absl::StatusOr<PointGraph> ResampleSurfaceGraph(const TriangleMesh& mesh,
                                                int num_samples,
                                                int neighbors,
                                                SurfacePoints* samples) {
  MESHSEEK_RETURN_IF_ERROR(ValidateMesh(mesh));
  MESHSEEK_ASSIGN_OR_RETURN(SurfacePoints points, SampleSurface(mesh, num_samples));
  MESHSEEK_ASSIGN_OR_RETURN(PointGraph graph, SymmetricKnnGraph(points.positions, neighbors));
  if (samples != nullptr) *samples = std::move(points);
  return graph;
}

absl::StatusOr<LocalFeatures> DescribeRldSift(const TriangleMesh& mesh,
                                              const PointGraph& graph,
                                              const RldSiftOptions& options,
                                              std::vector<InterestPoint>* detected,
                                              int num_threads) {
  MESHSEEK_RETURN_IF_ERROR(options.Validate());
  MESHSEEK_RETURN_IF_ERROR(ValidateMesh(mesh));
  MESHSEEK_RETURN_IF_ERROR(ValidatePointGraph(graph));
  std::vector<InterestPoint> points = DetectInterestPoints(graph, options.scale_space);
  LocalFeatures features = DescribeInterestPoints(
      mesh, graph.positions, points, options.weighted_frame, options.two_views,
      options.depth_image, options.descriptor,
      [](const InterestPoint& ip, const Vec3f& p, const PrincipalAxes& axes) {
        return std::optional<ViewFrame>(ViewFrame{Vec3d(p), axes.axes[0], axes.axes[2], ip.scale});
      },
      num_threads);
  if (detected != nullptr) *detected = std::move(points);
  return features;
}

absl::StatusOr<LocalFeatures> ExtractRldSift(const TriangleMesh& mesh,
                                             const RldSiftOptions& options,
                                             SurfacePoints* resampled,
                                             std::vector<InterestPoint>* detected,
                                             int num_threads) {
  MESHSEEK_RETURN_IF_ERROR(options.Validate());
  MESHSEEK_ASSIGN_OR_RETURN(
      const PointGraph graph,
      ResampleSurfaceGraph(mesh, options.num_samples, options.neighbors, resampled));
  return DescribeRldSift(mesh, graph, options, detected, num_threads);
}

}  // namespace meshseek
