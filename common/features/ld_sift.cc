#include "common/features/ld_sift.h"

#include <algorithm>

#include "common/base/status_macros.h"
#include "common/features/local_depth_sift.h"
#include "common/geometry/mesh_vertex_graph.h"
#include "common/geometry/point_grid.h"

namespace meshseek {

absl::Status LdSiftOptions::Validate() const {
  MESHSEEK_RETURN_IF_ERROR(scale_space.Validate());
  MESHSEEK_RETURN_IF_ERROR(depth_image.Validate());
  return descriptor.Validate();
}

absl::StatusOr<LocalFeatures> ExtractLdSift(const TriangleMesh& mesh,
                                            const LdSiftOptions& options,
                                            std::vector<InterestPoint>* detected) {
  MESHSEEK_RETURN_IF_ERROR(options.Validate());
  MESHSEEK_RETURN_IF_ERROR(ValidateMesh(mesh));
  const MeshVertexGraph vertex_graph = BuildMeshVertexGraph(mesh);
  const PointGraph& graph = vertex_graph.graph;
  std::vector<InterestPoint> points = DetectInterestPoints(graph, options.scale_space);
  LocalFeatures features;
  if (!points.empty()) {
    const PointGrid grid(graph.positions, std::max(MedianScale(points), 1e-12f));
    LocalDepthSift describer(mesh, options.depth_image, options.descriptor);
    std::vector<uint32_t> support;
    for (const InterestPoint& ip : points) {
      const Vec3f& p = graph.positions[ip.vertex];
      const Vec3d normal(vertex_graph.normals[ip.vertex]);
      const auto axes = SupportAxes(graph.positions, grid, p, ip.scale, false, &support);
      if (!axes || SquaredNorm(normal) < 0.5) continue;
      // The image's up axis: the main PCA axis, made orthogonal to the normal.
      Vec3d up = axes->axes[0] - normal * Dot(axes->axes[0], normal);
      if (SquaredNorm(up) < 1e-12) up = axes->axes[1] - normal * Dot(axes->axes[1], normal);
      describer.Describe({Vec3d(p), Normalized(up), normal, ip.scale}, false, ip.level, &features);
    }
  }
  if (detected != nullptr) *detected = std::move(points);
  return features;
}

}  // namespace meshseek
