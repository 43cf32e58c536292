// Uniform grid over a point set for fixed-radius neighbour queries.
//
// Local frames need "all dense surface samples within the support radius s of
// a point" about a thousand times per model with one s per model; a grid with
// cells of size s answers that by visiting 27 cells, with no tree to build
// or balance. Cells are stored sorted by key (no hash map), so building is
// one sort and a query is a few binary searches.
#ifndef MESHSEEK_COMMON_GEOMETRY_POINT_GRID_H_
#define MESHSEEK_COMMON_GEOMETRY_POINT_GRID_H_

#include <cstdint>
#include <vector>

#include "common/geometry/vec3.h"

namespace meshseek {

class PointGrid {
 public:
  // `points` must outlive the grid. `cell_size` > 0; queries are fastest for
  // radii close to it.
  PointGrid(const std::vector<Vec3f>& points, float cell_size);

  // Appends to `out` the indices of all points within `radius` of `center`
  // (inclusive), in increasing index order within each cell. `out` is not cleared.
  void RadiusQuery(const Vec3f& center, float radius, std::vector<uint32_t>* out) const;

 private:
  uint64_t Key(int64_t ix, int64_t iy, int64_t iz) const;
  int64_t CellCoord(float value, int axis) const;

  const std::vector<Vec3f>& points_;
  float cell_size_;
  Vec3f origin_;
  std::vector<uint64_t> cell_keys_;    // sorted, unique
  std::vector<uint32_t> cell_starts_;  // cell c: sorted_[cell_starts_[c] .. cell_starts_[c+1])
  std::vector<uint32_t> sorted_;       // point indices grouped by cell
};

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_GEOMETRY_POINT_GRID_H_
