// The index of a collection of a global method (LFD): each model's one
// fixed-size descriptor, ranked by the method's own distance
// (FeatureMethodInfo::distance) by an exhaustive parallel scan. Global
// descriptors are compared by minima over rotations and views that admit no
// inverted file or embedding, and their collections are the size of
// benchmarks (PSB's 1,814 models: one query scans them in milliseconds), so
// the scan is exact and the only mode.
//
// Descriptors are stored contiguously (removal moves the last into the gap).
// Not thread-safe for writers; const methods may run concurrently.
#ifndef MESHSEEK_COMMON_SEARCH_GLOBAL_DESCRIPTOR_INDEX_H_
#define MESHSEEK_COMMON_SEARCH_GLOBAL_DESCRIPTOR_INDEX_H_

#include <cstdint>
#include <functional>
#include <vector>

#include "absl/container/flat_hash_map.h"
#include "absl/status/statusor.h"
#include "absl/types/span.h"
#include "common/features/local_feature_extractor.h"
#include "common/search/kl_inverted_index.h"

namespace meshseek {

class GlobalDescriptorIndex {
 public:
  /// InvalidArgument unless `method` is global and dimension is its
  /// descriptor_bytes.
  static absl::StatusOr<GlobalDescriptorIndex> Create(FeatureMethod method, std::size_t dimension);

  FeatureMethod method() const { return method_; }
  std::size_t dimension() const { return dimension_; }
  std::size_t size() const { return docs_.size(); }

  /// Adds or replaces `doc`. InvalidArgument for a descriptor of another size.
  absl::Status Upsert(uint32_t doc, absl::Span<const uint8_t> descriptor);
  /// false when `doc` was not there.
  bool Remove(uint32_t doc);

  /// The query's distance to every doc, in no particular order.
  absl::StatusOr<std::vector<KlNeighbor>> Distances(absl::Span<const uint8_t> query,
                                                    int num_threads) const;
  /// The query's distance to each of `docs`, in that order (the values
  /// Distances gives them). NotFound for a doc that is not stored.
  absl::StatusOr<std::vector<KlNeighbor>> DistancesTo(absl::Span<const uint8_t> query,
                                                      absl::Span<const uint32_t> docs) const;
  /// The k nearest docs (ties by doc), and every doc tied with the k-th.
  absl::StatusOr<std::vector<KlNeighbor>> Search(absl::Span<const uint8_t> query,
                                                 std::size_t k,
                                                 int num_threads) const;
  /// Search by one view (a picture's) with the method's view_distance, for
  /// a method whose descriptors are views (LFD). InvalidArgument for another
  /// method or a view of another size.
  absl::StatusOr<std::vector<KlNeighbor>> SearchView(absl::Span<const uint8_t> view,
                                                     std::size_t k,
                                                     int num_threads) const;

  /// The descriptor stored for `doc` (valid until the next write), or NotFound.
  absl::StatusOr<absl::Span<const uint8_t>> Descriptor(uint32_t doc) const;
  void ForEach(const std::function<void(uint32_t doc, absl::Span<const uint8_t>)>& fn) const;
  std::size_t MemoryBytes() const;

 private:
  GlobalDescriptorIndex(FeatureMethod method, std::size_t dimension)
      : method_(method), dimension_(dimension) {}
  absl::Status CheckSize(std::size_t bytes) const;
  // `distance(slot)` of every doc, in slot order.
  template <typename Distance>
  std::vector<KlNeighbor> Scan(const Distance& distance, int num_threads) const;

  FeatureMethod method_;
  std::size_t dimension_;
  float (*distance_)(const uint8_t*, const uint8_t*, std::size_t) = nullptr;
  std::vector<uint32_t> docs_;                       // slot -> doc
  absl::flat_hash_map<uint32_t, std::size_t> slot_;  // doc -> slot
  std::vector<uint8_t> data_;                        // slot-major descriptors
};

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_SEARCH_GLOBAL_DESCRIPTOR_INDEX_H_
