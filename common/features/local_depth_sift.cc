#include "common/features/local_depth_sift.h"

#include <algorithm>

namespace meshseek {

std::optional<PrincipalAxes> SupportAxes(const std::vector<Vec3f>& points,
                                         const PointGrid& grid,
                                         const Vec3f& p,
                                         double s,
                                         bool weighted,
                                         std::vector<uint32_t>* scratch) {
  scratch->clear();
  grid.RadiusQuery(p, static_cast<float>(s), scratch);
  if (scratch->size() < 3) return std::nullopt;
  return weighted ? ComputeWeightedPrincipalAxes(points, *scratch, Vec3d(p), s)
                  : ComputePrincipalAxes(points, scratch);
}

LocalDepthSift::LocalDepthSift(const TriangleMesh& mesh,
                               const TriangleBvh& bvh,
                               const DepthImageOptions& image_options,
                               const SiftDescriptorOptions& descriptor_options)
    : renderer_(mesh, bvh, image_options), describer_(descriptor_options) {}

void LocalDepthSift::Describe(const ViewFrame& frame,
                              bool two_views,
                              int level,
                              LocalFeatures* out) {
  renderer_.RenderPair(frame, &front_, two_views ? &back_ : nullptr);
  for (int view = 0; view < (two_views ? 2 : 1); ++view) {
    DepthImage& image = view == 0 ? front_ : back_;
    if (!FinishDepthImage(&image)) continue;
    const int described = describer_.Describe(image, &out->descriptors);
    const Vec3f forward(view == 0 ? -frame.normal : frame.normal);
    for (int k = 0; k < described; ++k) {
      out->keypoints.push_back(
          {Vec3f(frame.point), forward, Vec3f(frame.up), static_cast<float>(frame.radius), level});
    }
  }
}

LocalFeatures DescribeFrames(const TriangleMesh& mesh,
                             std::size_t count,
                             bool two_views,
                             const DepthImageOptions& image_options,
                             const SiftDescriptorOptions& descriptor_options,
                             int num_threads,
                             const FrameOf& frame_of) {
  const TriangleBvh bvh(mesh);
  return DescribeInRuns(count, num_threads, [&](std::size_t begin, std::size_t end,
                                                LocalFeatures* out) {
    LocalDepthSift describer(mesh, bvh, image_options, descriptor_options);
    std::vector<uint32_t> support;
    for (std::size_t i = begin; i < end; ++i) {
      if (const std::optional<LevelFrame> f = frame_of(i, &support)) {
        describer.Describe(f->frame, two_views, f->level, out);
      }
    }
  });
}

LocalFeatures DescribeInterestPoints(const TriangleMesh& mesh,
                                     const std::vector<Vec3f>& positions,
                                     const std::vector<InterestPoint>& points,
                                     bool weighted,
                                     bool two_views,
                                     const DepthImageOptions& image_options,
                                     const SiftDescriptorOptions& descriptor_options,
                                     const InterestPointFrame& make_frame,
                                     int num_threads) {
  if (points.empty()) return LocalFeatures();
  const PointGrid grid(positions, std::max(MedianScale(points), 1e-12f));
  return DescribeFrames(
      mesh, points.size(), two_views, image_options, descriptor_options, num_threads,
      [&](std::size_t i, std::vector<uint32_t>* support) -> std::optional<LevelFrame> {
        const InterestPoint& ip = points[i];
        const Vec3f& p = positions[ip.vertex];
        const auto axes = SupportAxes(positions, grid, p, ip.scale, weighted, support);
        if (!axes) return std::nullopt;
        const std::optional<ViewFrame> frame = make_frame(ip, p, *axes);
        if (!frame) return std::nullopt;
        return LevelFrame{*frame, ip.level};
      });
}

}  // namespace meshseek
