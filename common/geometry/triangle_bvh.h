// Bounding-volume hierarchy over a mesh's triangles, for finding the
// triangles near a point without looping over the whole mesh (DESIGN.md 2.2:
// each depth image rasterises only the triangles inside its view box).
//
// Built once per model: median split of triangle centroids along the longest
// axis, leaves of up to kLeafSize triangles, nodes in one array (depth-first,
// left child next to its parent). A BVH rather than a uniform grid because
// PSB-style models mix tiny and huge triangles, which grids handle badly.
#ifndef MESHSEEK_COMMON_GEOMETRY_TRIANGLE_BVH_H_
#define MESHSEEK_COMMON_GEOMETRY_TRIANGLE_BVH_H_

#include <cstdint>
#include <vector>

#include "common/geometry/mesh.h"

namespace meshseek {

struct Aabb {
  Vec3f min{1e30f, 1e30f, 1e30f};
  Vec3f max{-1e30f, -1e30f, -1e30f};

  void Extend(const Vec3f& p);
  void Extend(const Aabb& b);
  bool Overlaps(const Aabb& b) const {
    return min.x <= b.max.x && b.min.x <= max.x && min.y <= b.max.y && b.min.y <= max.y &&
           min.z <= b.max.z && b.min.z <= max.z;
  }
};

class TriangleBvh {
 public:
  static constexpr int kLeafSize = 4;

  // Indexes every triangle of `mesh` (which must outlive nothing: the BVH
  // keeps only triangle boxes and indices).
  explicit TriangleBvh(const TriangleMesh& mesh);

  // Appends to `out` the index of every triangle whose bounding box overlaps
  // `box` (a superset of the triangles that intersect it). `out` is not cleared.
  void Query(const Aabb& box, std::vector<uint32_t>* out) const;

  std::size_t num_nodes() const { return nodes_.size(); }

 private:
  struct Node {
    Aabb box;
    uint32_t first;  // leaf: first index into order_; inner: index of the right child
    uint32_t count;  // leaf: number of triangles; inner: 0
  };
  uint32_t Build(uint32_t begin, uint32_t end, const std::vector<Vec3f>& centroids);

  std::vector<Node> nodes_;
  std::vector<Aabb> triangle_boxes_;
  std::vector<uint32_t> order_;
};

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_GEOMETRY_TRIANGLE_BVH_H_
