#include "common/features/ld_sift.h"


#include "common/base/status_macros.h"
#include "common/features/local_depth_sift.h"
#include "common/geometry/mesh_vertex_graph.h"

namespace meshseek {

absl::Status LdSiftOptions::Validate() const {
  MESHSEEK_RETURN_IF_ERROR(scale_space.Validate());
  MESHSEEK_RETURN_IF_ERROR(depth_image.Validate());
  return descriptor.Validate();
}

absl::StatusOr<LocalFeatures> ExtractLdSift(const TriangleMesh& mesh,
                                            const LdSiftOptions& options,
                                            std::vector<InterestPoint>* detected,
                                            int num_threads) {
  MESHSEEK_RETURN_IF_ERROR(options.Validate());
  MESHSEEK_RETURN_IF_ERROR(ValidateMesh(mesh));
  const MeshVertexGraph vertex_graph = BuildMeshVertexGraph(mesh);
  const PointGraph& graph = vertex_graph.graph;
  std::vector<InterestPoint> points = DetectInterestPoints(graph, options.scale_space);
  LocalFeatures features = DescribeInterestPoints(
      mesh, graph.positions, points, /*weighted=*/false, /*two_views=*/false,
      options.depth_image, options.descriptor,
      [&](const InterestPoint& ip, const Vec3f& p,
          const PrincipalAxes& axes) -> std::optional<ViewFrame> {
        const Vec3d normal(vertex_graph.normals[ip.vertex]);
        if (SquaredNorm(normal) < 0.5) return std::nullopt;
        // The image's up axis: the main PCA axis, made orthogonal to the normal.
        Vec3d up = axes.axes[0] - normal * Dot(axes.axes[0], normal);
        if (SquaredNorm(up) < 1e-12) up = axes.axes[1] - normal * Dot(axes.axes[1], normal);
        return ViewFrame{Vec3d(p), Normalized(up), normal, ip.scale};
      },
      num_threads);
  if (detected != nullptr) *detected = std::move(points);
  return features;
}

}  // namespace meshseek
