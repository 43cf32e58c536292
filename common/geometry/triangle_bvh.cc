#include "common/geometry/triangle_bvh.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace meshseek {

void Aabb::Extend(const Vec3f& p) {
  min = {std::min(min.x, p.x), std::min(min.y, p.y), std::min(min.z, p.z)};
  max = {std::max(max.x, p.x), std::max(max.y, p.y), std::max(max.z, p.z)};
}

void Aabb::Extend(const Aabb& b) {
  Extend(b.min);
  Extend(b.max);
}

TriangleBvh::TriangleBvh(const TriangleMesh& mesh) {
  const std::size_t n = mesh.triangles.size();
  std::vector<Aabb> boxes(n);
  std::vector<Vec3f> centroids(n);
  for (std::size_t t = 0; t < n; ++t) {
    Aabb box;
    Vec3f sum;
    for (uint32_t v : mesh.triangles[t]) {
      box.Extend(mesh.vertices[v]);
      sum += mesh.vertices[v];
    }
    boxes[t] = box;
    centroids[t] = sum / 3.0f;
  }
  order_.resize(n);
  std::iota(order_.begin(), order_.end(), 0u);
  nodes_.reserve(n > 0 ? 2 * (n / kLeafSize + 1) : 0);
  if (n > 0) Build(0, static_cast<uint32_t>(n), boxes, centroids);
}

uint32_t TriangleBvh::Build(uint32_t begin,
                            uint32_t end,
                            const std::vector<Aabb>& boxes,
                            const std::vector<Vec3f>& centroids) {
  const uint32_t index = static_cast<uint32_t>(nodes_.size());
  nodes_.push_back({});
  Aabb box, centroid_box;
  for (uint32_t i = begin; i < end; ++i) {
    box.Extend(boxes[order_[i]]);
    centroid_box.Extend(centroids[order_[i]]);
  }
  nodes_[index] = {box, begin, end, 0};
  if (end - begin <= static_cast<uint32_t>(kLeafSize)) return index;
  const Vec3f extent = centroid_box.max - centroid_box.min;
  const int axis =
      extent.x >= extent.y && extent.x >= extent.z ? 0 : (extent.y >= extent.z ? 1 : 2);
  const uint32_t mid = begin + (end - begin) / 2;
  std::nth_element(order_.begin() + begin,
                   order_.begin() + mid,
                   order_.begin() + end,
                   [&](uint32_t a, uint32_t b) {
                     const float ca = centroids[a][axis], cb = centroids[b][axis];
                     return ca < cb || (ca == cb && a < b);
                   });
  Build(begin, mid, boxes, centroids);
  nodes_[index].right = Build(mid, end, boxes, centroids);
  return index;
}

bool OrientedBox::MayOverlap(const Aabb& box) const {
  const Vec3d box_center = (Vec3d(box.min) + Vec3d(box.max)) * 0.5;
  const Vec3d box_half = (Vec3d(box.max) - Vec3d(box.min)) * 0.5;
  const Vec3d d = center - box_center;
  for (int j = 0; j < 3; ++j) {  // world axes
    double reach = box_half[j];
    for (int i = 0; i < 3; ++i) reach += half_extents[i] * std::abs(axes[i][j]);
    if (std::abs(d[j]) > reach) return false;
  }
  for (int i = 0; i < 3; ++i) {  // box axes
    double reach = half_extents[i];
    for (int j = 0; j < 3; ++j) reach += box_half[j] * std::abs(axes[i][j]);
    if (std::abs(Dot(d, axes[i])) > reach) return false;
  }
  return true;
}

namespace {

// OrientedBox::MayOverlap with what does not depend on the node computed
// once per query.
auto OrientedBoxTest(const OrientedBox& box) {
  // MayOverlap with what does not depend on the node computed once: the same
  // products and sums in the same order, so the same answers.
  struct Test {
    OrientedBox box;
    double abs_axes[3][3];  // |axes[i][j]|
    double spread[3][3];    // half_extents[i] |axes[i][j]|
    // A node is inside when its box is this far within every face (a
    // billionth of the half extent), so that rounding cannot fail a box
    // inside it on the overlap tests; were it to, the caller would get a few
    // triangles it rejects anyway.
    double inner[3];
    BoxRelation operator()(const Aabb& b) const {
      const Vec3d box_center = (Vec3d(b.min) + Vec3d(b.max)) * 0.5;
      const Vec3d box_half = (Vec3d(b.max) - Vec3d(b.min)) * 0.5;
      const Vec3d d = box.center - box_center;
      for (int j = 0; j < 3; ++j) {
        double reach = box_half[j];
        for (int i = 0; i < 3; ++i) reach += spread[i][j];
        if (std::abs(d[j]) > reach) return BoxRelation::kOutside;
      }
      bool inside = true;
      for (int i = 0; i < 3; ++i) {
        double reach = box.half_extents[i];
        double half_width = 0;  // of b along axis i
        for (int j = 0; j < 3; ++j) {
          const double w = box_half[j] * abs_axes[i][j];
          reach += w;
          half_width += w;
        }
        const double offset = std::abs(Dot(d, box.axes[i]));
        if (offset > reach) return BoxRelation::kOutside;
        inside = inside && offset + half_width <= inner[i];
      }
      return inside ? BoxRelation::kInside : BoxRelation::kOverlaps;
    }
  };
  Test test{box, {}, {}, {}};
  for (int i = 0; i < 3; ++i) {
    test.inner[i] = box.half_extents[i] * (1 - 1e-9);
    for (int j = 0; j < 3; ++j) {
      test.abs_axes[i][j] = std::abs(box.axes[i][j]);
      test.spread[i][j] = box.half_extents[i] * test.abs_axes[i][j];
    }
  }
  return test;
}

}  // namespace

void TriangleBvh::Query(const Aabb& box, std::vector<uint32_t>* out) const {
  Traverse(
      [&box](const Aabb& b) {
        if (!b.Overlaps(box)) return BoxRelation::kOutside;
        const bool inside = box.min.x <= b.min.x && b.max.x <= box.max.x && box.min.y <= b.min.y &&
                            b.max.y <= box.max.y && box.min.z <= b.min.z && b.max.z <= box.max.z;
        return inside ? BoxRelation::kInside : BoxRelation::kOverlaps;
      },
      [&](uint32_t begin, uint32_t end) {
        out->insert(out->end(), order_.begin() + begin, order_.begin() + end);
      });
}

void TriangleBvh::Query(const OrientedBox& box, std::vector<uint32_t>* out) const {
  Traverse(OrientedBoxTest(box), [&](uint32_t begin, uint32_t end) {
    out->insert(out->end(), order_.begin() + begin, order_.begin() + end);
  });
}

// Leaves are tested by their node box only: a leaf's few triangles are cheaper
// to hand to the caller, which rejects far ones in its own first step, than to
// test box by box. A node inside the query box is not descended: a large view
// cube of a dense mesh holds thousands of triangles, and their subtrees were
// most of the nodes tested.
template <typename Classify, typename Emit>
void TriangleBvh::Traverse(const Classify& classify, const Emit& emit) const {
  if (nodes_.empty()) return;
  uint32_t stack[64];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const uint32_t index = stack[--top];
    const Node& node = nodes_[index];
    const BoxRelation relation = classify(node.box);
    if (relation == BoxRelation::kOutside) continue;
    if (relation == BoxRelation::kInside || node.right == 0) {
      emit(node.begin, node.end);
    } else {
      stack[top++] = node.right;
      stack[top++] = index + 1;  // left child (depth-first layout)
    }
  }
}

}  // namespace meshseek
