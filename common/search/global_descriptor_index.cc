#include "common/search/global_descriptor_index.h"

#include <algorithm>
#include <cstring>
#include <tuple>

#include "absl/strings/str_cat.h"
#include "common/base/parallel.h"

namespace meshseek {

absl::StatusOr<GlobalDescriptorIndex> GlobalDescriptorIndex::Create(FeatureMethod method,
                                                                    std::size_t dimension) {
  const FeatureMethodInfo& info = FeatureMethodInfoOf(method);
  if (info.kind != DescriptorKind::kGlobal || info.distance == nullptr) {
    return absl::InvalidArgumentError(
        absl::StrCat("global index: method ", info.name, " has no global descriptor"));
  }
  if (dimension != info.descriptor_bytes) {
    return absl::InvalidArgumentError(absl::StrCat("global index: ",
                                                   info.name,
                                                   " descriptor of ",
                                                   dimension,
                                                   " bytes, expected ",
                                                   info.descriptor_bytes));
  }
  GlobalDescriptorIndex index(method, dimension);
  index.distance_ = info.distance;
  return index;
}

absl::Status GlobalDescriptorIndex::CheckSize(std::size_t bytes) const {
  if (bytes == dimension_) return absl::OkStatus();
  return absl::InvalidArgumentError(absl::StrCat("descriptor of ",
                                                 bytes,
                                                 " bytes but the ",
                                                 FeatureMethodName(method_),
                                                 " collection holds ",
                                                 dimension_));
}

absl::Status GlobalDescriptorIndex::Upsert(uint32_t doc, absl::Span<const uint8_t> descriptor) {
  if (absl::Status s = CheckSize(descriptor.size()); !s.ok()) return s;
  auto [it, inserted] = slot_.try_emplace(doc, docs_.size());
  if (inserted) {
    docs_.push_back(doc);
    data_.resize(docs_.size() * dimension_);
  }
  std::memcpy(data_.data() + it->second * dimension_, descriptor.data(), dimension_);
  return absl::OkStatus();
}

bool GlobalDescriptorIndex::Remove(uint32_t doc) {
  auto it = slot_.find(doc);
  if (it == slot_.end()) return false;
  const std::size_t slot = it->second, last = docs_.size() - 1;
  slot_.erase(it);
  if (slot != last) {
    std::memcpy(data_.data() + slot * dimension_, data_.data() + last * dimension_, dimension_);
    docs_[slot] = docs_[last];
    slot_[docs_[slot]] = slot;
  }
  docs_.pop_back();
  data_.resize(docs_.size() * dimension_);
  return true;
}

template <typename Distance>
std::vector<KlNeighbor> GlobalDescriptorIndex::Scan(const Distance& distance,
                                                    int num_threads) const {
  std::vector<KlNeighbor> out(docs_.size());
  // Blocks of docs per task: one distance is microseconds.
  constexpr std::size_t kBlock = 64;
  const std::size_t blocks = (docs_.size() + kBlock - 1) / kBlock;
  ParallelFor(blocks, num_threads, [&](std::size_t b) {
    const std::size_t end = std::min(docs_.size(), (b + 1) * kBlock);
    for (std::size_t i = b * kBlock; i < end; ++i) {
      out[i] = {docs_[i], distance(data_.data() + i * dimension_)};
    }
  });
  return out;
}

absl::StatusOr<std::vector<KlNeighbor>> GlobalDescriptorIndex::Distances(
    absl::Span<const uint8_t> query, int num_threads) const {
  if (absl::Status s = CheckSize(query.size()); !s.ok()) return s;
  return Scan(
      [&](const uint8_t* stored) { return distance_(query.data(), stored, dimension_); },
      num_threads);
}

absl::StatusOr<std::vector<KlNeighbor>> GlobalDescriptorIndex::DistancesTo(
    absl::Span<const uint8_t> query, absl::Span<const uint32_t> docs) const {
  if (absl::Status s = CheckSize(query.size()); !s.ok()) return s;
  std::vector<KlNeighbor> out(docs.size());
  for (std::size_t i = 0; i < docs.size(); ++i) {
    const auto it = slot_.find(docs[i]);
    if (it == slot_.end()) {
      return absl::NotFoundError(absl::StrCat("distances: model ", docs[i], " is not stored"));
    }
    out[i] = {docs[i], distance_(query.data(), data_.data() + it->second * dimension_, dimension_)};
  }
  return out;
}

absl::StatusOr<absl::Span<const uint8_t>> GlobalDescriptorIndex::Descriptor(uint32_t doc) const {
  const auto it = slot_.find(doc);
  if (it == slot_.end()) return absl::NotFoundError(absl::StrCat("model ", doc, " is not stored"));
  return absl::MakeConstSpan(data_.data() + it->second * dimension_, dimension_);
}

namespace {

// The k nearest of `all` (ties by doc) and every one tied with the k-th.
std::vector<KlNeighbor> Nearest(std::vector<KlNeighbor> all, std::size_t k) {
  auto less = [](const KlNeighbor& a, const KlNeighbor& b) {
    return std::tie(a.distance, a.doc) < std::tie(b.distance, b.doc);
  };
  std::sort(all.begin(), all.end(), less);
  std::size_t keep = std::min(k, all.size());
  while (keep > 0 && keep < all.size() && all[keep].distance == all[keep - 1].distance) ++keep;
  all.resize(keep);
  return all;
}

}  // namespace

absl::StatusOr<std::vector<KlNeighbor>> GlobalDescriptorIndex::Search(
    absl::Span<const uint8_t> query, std::size_t k, int num_threads) const {
  absl::StatusOr<std::vector<KlNeighbor>> all = Distances(query, num_threads);
  if (!all.ok()) return all.status();
  return Nearest(*std::move(all), k);
}

absl::StatusOr<std::vector<KlNeighbor>> GlobalDescriptorIndex::SearchView(
    absl::Span<const uint8_t> view, std::size_t k, int num_threads) const {
  const FeatureMethodInfo& info = FeatureMethodInfoOf(method_);
  if (info.view_distance == nullptr) {
    return absl::InvalidArgumentError(absl::StrCat(
        "a ", info.name, " collection cannot be searched by a picture: its descriptors are not views"));
  }
  if (view.size() != info.view_bytes) {
    return absl::InvalidArgumentError(absl::StrCat("a view of ", view.size(), " bytes but ",
                                                   info.name, " views have ", info.view_bytes));
  }
  return Nearest(Scan([&](const uint8_t* stored) { return info.view_distance(view.data(), stored); },
                      num_threads),
                 k);
}

void GlobalDescriptorIndex::ForEach(
    const std::function<void(uint32_t, absl::Span<const uint8_t>)>& fn) const {
  for (std::size_t i = 0; i < docs_.size(); ++i) {
    fn(docs_[i], absl::MakeConstSpan(data_.data() + i * dimension_, dimension_));
  }
}

std::size_t GlobalDescriptorIndex::MemoryBytes() const {
  return data_.capacity() + docs_.capacity() * sizeof(uint32_t) +
         slot_.capacity() * (sizeof(uint32_t) + sizeof(std::size_t) + 1);
}

}  // namespace meshseek
