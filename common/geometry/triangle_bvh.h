// Bounding-volume hierarchy over a mesh's triangles, for finding the
// triangles near a point without looping over the whole mesh (docs/design.md 2.2:
// each depth image rasterises only the triangles inside its view box).
//
// Built once per model: median split of triangle centroids along the longest
// axis, leaves of up to kLeafSize triangles, nodes in one array (depth-first,
// left child next to its parent). A BVH rather than a uniform grid because
// PSB-style models mix tiny and huge triangles, which grids handle badly.
#ifndef MESHSEEK_COMMON_GEOMETRY_TRIANGLE_BVH_H_
#define MESHSEEK_COMMON_GEOMETRY_TRIANGLE_BVH_H_

#include <array>
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

// A box with arbitrary orientation: centre, three orthonormal axes and the
// half extent along each.
struct OrientedBox {
  Vec3d center;
  std::array<Vec3d, 3> axes;
  std::array<double, 3> half_extents{0, 0, 0};

  // Conservative overlap test by separating axes (the 3 world axes and the 3
  // box axes; edge cross products are skipped, so rare near-misses count as
  // overlaps).
  bool MayOverlap(const Aabb& box) const;
};

// Where a node's box lies against a query box.
enum class BoxRelation { kOutside, kOverlaps, kInside };

class TriangleBvh {
 public:
  static constexpr int kLeafSize = 8;

  // Indexes every triangle of `mesh` (which must outlive nothing: the BVH
  // keeps only triangle boxes and indices).
  explicit TriangleBvh(const TriangleMesh& mesh);

  // Appends to `out` the index of every triangle whose bounding box overlaps
  // `box`, and possibly a few more from the same leaves (a superset of the
  // triangles that intersect it). `out` is not cleared.
  void Query(const Aabb& box, std::vector<uint32_t>* out) const;
  // Same for an oriented box: triangles whose bounding box may overlap it.
  // Much tighter than querying the oriented box's own bounding box when the
  // box is turned (a depth image's view cube, say).
  void Query(const OrientedBox& box, std::vector<uint32_t>* out) const;

  std::size_t num_nodes() const { return nodes_.size(); }

 private:
  // Every node owns order_[begin, end): its subtree's triangles, contiguous
  // in depth-first order, so a node inside the query box is emitted whole.
  struct Node {
    Aabb box;
    uint32_t begin;
    uint32_t end;
    uint32_t right;  // inner: index of the right child; leaf: 0
  };
  uint32_t Build(uint32_t begin,
                 uint32_t end,
                 const std::vector<Aabb>& boxes,
                 const std::vector<Vec3f>& centroids);
  // Calls emit(begin, end) (positions in order_), depth first, for every leaf
  // whose box `classify` does not find kOutside and, in one call, for every
  // node it finds kInside: the same triangles in the same order as visiting
  // that node's leaves, which a box inside the query box all overlap.
  template <typename Classify, typename Emit>
  void Traverse(const Classify& classify, const Emit& emit) const;

  std::vector<Node> nodes_;
  std::vector<uint32_t> order_;
};

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_GEOMETRY_TRIANGLE_BVH_H_
