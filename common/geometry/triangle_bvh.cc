#include "common/geometry/triangle_bvh.h"

#include <algorithm>
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
  triangle_boxes_.resize(n);
  std::vector<Vec3f> centroids(n);
  for (std::size_t t = 0; t < n; ++t) {
    Aabb box;
    Vec3f sum;
    for (uint32_t v : mesh.triangles[t]) {
      box.Extend(mesh.vertices[v]);
      sum += mesh.vertices[v];
    }
    triangle_boxes_[t] = box;
    centroids[t] = sum / 3.0f;
  }
  order_.resize(n);
  std::iota(order_.begin(), order_.end(), 0u);
  nodes_.reserve(n > 0 ? 2 * (n / kLeafSize + 1) : 0);
  if (n > 0) Build(0, static_cast<uint32_t>(n), centroids);
}

uint32_t TriangleBvh::Build(uint32_t begin, uint32_t end, const std::vector<Vec3f>& centroids) {
  const uint32_t index = static_cast<uint32_t>(nodes_.size());
  nodes_.push_back({});
  Aabb box, centroid_box;
  for (uint32_t i = begin; i < end; ++i) {
    box.Extend(triangle_boxes_[order_[i]]);
    centroid_box.Extend(centroids[order_[i]]);
  }
  nodes_[index].box = box;
  if (end - begin <= static_cast<uint32_t>(kLeafSize)) {
    nodes_[index].first = begin;
    nodes_[index].count = end - begin;
    return index;
  }
  const Vec3f extent = centroid_box.max - centroid_box.min;
  const int axis = extent.x >= extent.y && extent.x >= extent.z ? 0 : (extent.y >= extent.z ? 1 : 2);
  const uint32_t mid = begin + (end - begin) / 2;
  std::nth_element(order_.begin() + begin, order_.begin() + mid, order_.begin() + end,
                   [&](uint32_t a, uint32_t b) {
                     const float ca = centroids[a][axis], cb = centroids[b][axis];
                     return ca < cb || (ca == cb && a < b);
                   });
  Build(begin, mid, centroids);
  const uint32_t right = Build(mid, end, centroids);
  nodes_[index].first = right;
  nodes_[index].count = 0;
  return index;
}

void TriangleBvh::Query(const Aabb& box, std::vector<uint32_t>* out) const {
  if (nodes_.empty()) return;
  uint32_t stack[64];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const uint32_t index = stack[--top];
    const Node& node = nodes_[index];
    if (!node.box.Overlaps(box)) continue;
    if (node.count > 0) {
      for (uint32_t i = node.first; i < node.first + node.count; ++i) {
        if (triangle_boxes_[order_[i]].Overlaps(box)) out->push_back(order_[i]);
      }
    } else {
      stack[top++] = node.first;  // right child
      stack[top++] = index + 1;   // left child (depth-first layout)
    }
  }
}

}  // namespace meshseek
