#include "common/search/kl_inverted_index.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "absl/strings/str_cat.h"
#include "common/base/parallel.h"
#include "common/base/status_macros.h"

namespace meshseek {
namespace {

constexpr float kInfinity = std::numeric_limits<float>::infinity();

// The two common sums of one model against the query (a_xy, a_yx).
struct CommonSums {
  double query_side = 0.0;  // sum x_k g(y_k), x the query
  double model_side = 0.0;  // sum y_k g(x_k)
};

// Scratch of one thread: the common sums of a segment's slots.
std::vector<CommonSums>& Scratch() {
  thread_local std::vector<CommonSums> scratch;
  return scratch;
}

bool Closer(const KlNeighbor& a, const KlNeighbor& b) {
  return a.distance < b.distance || (a.distance == b.distance && a.doc < b.doc);
}

}  // namespace

struct KlInvertedIndex::PreparedQuery {
  std::vector<uint32_t> words;
  std::vector<float> weights;
  std::vector<float> g;  // float-rounded g(weight)
  double c = 0.0, e = 0.0, a = 0.0, big_g = 0.0;
  bool empty() const { return words.empty(); }
};

struct KlInvertedIndex::Segment {
  struct Postings {
    std::vector<uint16_t> slots;
    std::vector<float> weights;
    std::vector<float> g;
  };
  explicit Segment(uint32_t vocabulary) : postings(vocabulary) {}

  std::vector<Postings> postings;  // per word
  // Per slot.
  std::vector<uint32_t> docs;
  std::vector<uint8_t> live;
  std::vector<uint8_t> empty;  // no words: no local features
  std::vector<double> c, e, a, big_g;
  std::size_t dead = 0;
};

KlInvertedIndex::KlInvertedIndex(uint32_t vocabulary, const KlDivergenceOptions& options)
    : vocabulary_(vocabulary),
      options_(options),
      scale_(1.0 / (1.0 + vocabulary * options.epsilon)) {}
KlInvertedIndex::KlInvertedIndex(KlInvertedIndex&&) noexcept = default;
KlInvertedIndex& KlInvertedIndex::operator=(KlInvertedIndex&&) noexcept = default;
KlInvertedIndex::~KlInvertedIndex() = default;

absl::StatusOr<KlInvertedIndex> KlInvertedIndex::Create(uint32_t vocabulary,
                                                        const KlDivergenceOptions& options) {
  MESHSEEK_RETURN_IF_ERROR(options.Validate());
  if (vocabulary == 0) return absl::InvalidArgumentError("KlInvertedIndex: vocabulary 0");
  return KlInvertedIndex(vocabulary, options);
}

absl::StatusOr<KlInvertedIndex::PreparedQuery> KlInvertedIndex::Prepare(
    const SparseHistogram& histogram, absl::string_view name) const {
  MESHSEEK_RETURN_IF_ERROR(histogram.Validate(name, options_.sum_tolerance));
  if (histogram.vocabulary != vocabulary_) {
    return absl::InvalidArgumentError(absl::StrCat(name, " has vocabulary ", histogram.vocabulary,
                                                   ", the index ", vocabulary_));
  }
  PreparedQuery q;
  q.words = histogram.words;
  q.weights = histogram.weights;
  q.g.resize(q.words.size());
  const double eps = options_.epsilon;
  double sum = 0.0;
  for (std::size_t i = 0; i < q.words.size(); ++i) {
    const double x = q.weights[i];
    q.g[i] = static_cast<float>(std::log1p(x / eps));
    sum += x;
    q.a += x * static_cast<double>(q.g[i]);
    q.big_g += q.g[i];
  }
  q.c = 1.0 / (sum + vocabulary_ * eps);
  q.e = eps * q.c;
  return q;
}

void KlInvertedIndex::Append(uint32_t doc, const PreparedQuery& q) {
  if (segments_.empty() || segments_.back()->docs.size() == kSegmentSlots) {
    segments_.push_back(std::make_unique<Segment>(vocabulary_));
  }
  Segment& seg = *segments_.back();
  const auto slot = static_cast<uint16_t>(seg.docs.size());
  for (std::size_t i = 0; i < q.words.size(); ++i) {
    Segment::Postings& p = seg.postings[q.words[i]];
    p.slots.push_back(slot);
    p.weights.push_back(q.weights[i]);
    p.g.push_back(q.g[i]);
  }
  seg.docs.push_back(doc);
  seg.live.push_back(1);
  seg.empty.push_back(q.empty() ? 1 : 0);
  seg.c.push_back(q.c);
  seg.e.push_back(q.e);
  seg.a.push_back(q.a);
  seg.big_g.push_back(q.big_g);
  locations_[doc] = Location{static_cast<uint32_t>(segments_.size() - 1), slot};
}

absl::Status KlInvertedIndex::Upsert(uint32_t doc, const SparseHistogram& histogram) {
  MESHSEEK_ASSIGN_OR_RETURN(const PreparedQuery prepared,
                            Prepare(histogram, absl::StrCat("model ", doc)));
  Remove(doc);
  Append(doc, prepared);
  return absl::OkStatus();
}

bool KlInvertedIndex::Remove(uint32_t doc) {
  auto it = locations_.find(doc);
  if (it == locations_.end()) return false;
  const Location at = it->second;
  locations_.erase(it);
  Segment& seg = *segments_[at.segment];
  seg.live[at.slot] = 0;
  ++seg.dead;
  if (seg.dead * 2 > seg.docs.size()) CompactSegment(at.segment);
  return true;
}

std::vector<SparseHistogram> KlInvertedIndex::SegmentHistograms(std::size_t s) const {
  const Segment& seg = *segments_[s];
  std::vector<SparseHistogram> histograms(seg.docs.size());
  for (SparseHistogram& h : histograms) h.vocabulary = vocabulary_;
  for (uint32_t word = 0; word < vocabulary_; ++word) {
    const Segment::Postings& p = seg.postings[word];
    for (std::size_t i = 0; i < p.slots.size(); ++i) {
      histograms[p.slots[i]].words.push_back(word);
      histograms[p.slots[i]].weights.push_back(p.weights[i]);
    }
  }
  return histograms;
}

void KlInvertedIndex::CompactSegment(std::size_t s) {
  // Rebuilds segment s from its live slots, in slot order; slots change, docs
  // and values do not. The rebuilt segment replaces s in place.
  const std::vector<SparseHistogram> histograms = SegmentHistograms(s);
  const Segment& old = *segments_[s];
  auto rebuilt = std::make_unique<Segment>(vocabulary_);
  for (std::size_t slot = 0; slot < old.docs.size(); ++slot) {
    if (!old.live[slot]) continue;
    const auto fresh = static_cast<uint16_t>(rebuilt->docs.size());
    const SparseHistogram& h = histograms[slot];
    for (std::size_t i = 0; i < h.words.size(); ++i) {
      const Segment::Postings& from = old.postings[h.words[i]];
      Segment::Postings& to = rebuilt->postings[h.words[i]];
      // The g stored for this posting: find it again (postings are in slot order).
      const auto at = std::lower_bound(from.slots.begin(), from.slots.end(), slot);
      to.slots.push_back(fresh);
      to.weights.push_back(h.weights[i]);
      to.g.push_back(from.g[at - from.slots.begin()]);
    }
    rebuilt->docs.push_back(old.docs[slot]);
    rebuilt->live.push_back(1);
    rebuilt->empty.push_back(old.empty[slot]);
    rebuilt->c.push_back(old.c[slot]);
    rebuilt->e.push_back(old.e[slot]);
    rebuilt->a.push_back(old.a[slot]);
    rebuilt->big_g.push_back(old.big_g[slot]);
    locations_[old.docs[slot]] = Location{static_cast<uint32_t>(s), fresh};
  }
  segments_[s] = std::move(rebuilt);
}

void KlInvertedIndex::ForEach(
    const std::function<void(uint32_t, const SparseHistogram&)>& fn) const {
  for (std::size_t s = 0; s < segments_.size(); ++s) {
    const std::vector<SparseHistogram> histograms = SegmentHistograms(s);
    for (std::size_t slot = 0; slot < histograms.size(); ++slot) {
      if (segments_[s]->live[slot]) fn(segments_[s]->docs[slot], histograms[slot]);
    }
  }
}

absl::StatusOr<SparseHistogram> KlInvertedIndex::Histogram(uint32_t doc) const {
  auto it = locations_.find(doc);
  if (it == locations_.end()) {
    return absl::NotFoundError(absl::StrCat("model ", doc, " is not in the index"));
  }
  const Segment& seg = *segments_[it->second.segment];
  const uint16_t slot = it->second.slot;
  SparseHistogram h;
  h.vocabulary = vocabulary_;
  for (uint32_t word = 0; word < vocabulary_; ++word) {
    const Segment::Postings& p = seg.postings[word];
    const auto at = std::lower_bound(p.slots.begin(), p.slots.end(), slot);
    if (at == p.slots.end() || *at != slot) continue;
    h.words.push_back(word);
    h.weights.push_back(p.weights[at - p.slots.begin()]);
  }
  return h;
}

template <typename Emit>
void KlInvertedIndex::ScanSegment(const PreparedQuery& q, std::size_t s, Emit&& emit) const {
  const Segment& seg = *segments_[s];
  const std::size_t n = seg.docs.size();
  if (q.empty()) {
    for (std::size_t slot = 0; slot < n; ++slot) {
      if (seg.live[slot]) emit(seg.docs[slot], kInfinity);
    }
    return;
  }
  std::vector<CommonSums>& sums = Scratch();
  sums.assign(n, CommonSums{});
  for (std::size_t i = 0; i < q.words.size(); ++i) {
    const Segment::Postings& p = seg.postings[q.words[i]];
    const double x = q.weights[i];
    const double gx = q.g[i];
    const uint16_t* slots = p.slots.data();
    const float* weights = p.weights.data();
    const float* g = p.g.data();
    for (std::size_t j = 0, m = p.slots.size(); j < m; ++j) {
      CommonSums& sum = sums[slots[j]];
      sum.query_side += x * static_cast<double>(g[j]);
      sum.model_side += static_cast<double>(weights[j]) * gx;
    }
  }
  for (std::size_t slot = 0; slot < n; ++slot) {
    if (!seg.live[slot]) continue;
    if (seg.empty[slot]) {
      emit(seg.docs[slot], kInfinity);
      continue;
    }
    const double d = q.c * (q.a - sums[slot].query_side) +
                     seg.c[slot] * (seg.a[slot] - sums[slot].model_side) +
                     (q.e - seg.e[slot]) * (q.big_g - seg.big_g[slot]);
    emit(seg.docs[slot], d > 0.0 ? static_cast<float>(d) : 0.0f);
  }
}

absl::StatusOr<std::vector<KlNeighbor>> KlInvertedIndex::Distances(const SparseHistogram& query,
                                                                   int num_threads) const {
  MESHSEEK_ASSIGN_OR_RETURN(const PreparedQuery q, Prepare(query, "query"));
  // Each segment writes its own range of the output: segment s starts after
  // the live models of segments before it.
  std::vector<std::size_t> offsets(segments_.size() + 1, 0);
  for (std::size_t s = 0; s < segments_.size(); ++s) {
    offsets[s + 1] = offsets[s] + segments_[s]->docs.size() - segments_[s]->dead;
  }
  std::vector<KlNeighbor> out(offsets.back());
  ParallelFor(segments_.size(), num_threads, [&](std::size_t s) {
    std::size_t at = offsets[s];
    ScanSegment(q, s, [&](uint32_t doc, float d) { out[at++] = KlNeighbor{doc, d}; });
  });
  return out;
}

absl::StatusOr<std::vector<KlNeighbor>> KlInvertedIndex::Search(const SparseHistogram& query,
                                                                std::size_t k,
                                                                int num_threads) const {
  if (k == 0) return absl::InvalidArgumentError("search: k must be at least 1");
  MESHSEEK_ASSIGN_OR_RETURN(std::vector<KlNeighbor> all, Distances(query, num_threads));
  if (all.size() > k) {
    std::nth_element(all.begin(), all.begin() + (k - 1), all.end(), Closer);
    const float kth = all[k - 1].distance;
    // Keep the k nearest and every other model tied with the k-th.
    const auto tail = std::partition(all.begin() + k, all.end(),
                                     [kth](const KlNeighbor& n) { return n.distance == kth; });
    all.erase(tail, all.end());
  }
  std::sort(all.begin(), all.end(), Closer);
  return all;
}

absl::StatusOr<std::vector<float>> KlInvertedIndex::DistanceMatrix(const std::vector<uint32_t>& docs,
                                                                   int num_threads) const {
  const std::size_t n = docs.size();
  absl::flat_hash_map<uint32_t, std::size_t> column;
  column.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    if (!locations_.contains(docs[i])) {
      return absl::NotFoundError(absl::StrCat("model ", docs[i], " is not in the index"));
    }
    column[docs[i]] = i;
  }
  // Every row's histogram, read from the postings once per segment.
  std::vector<std::vector<SparseHistogram>> stored(segments_.size());
  ParallelFor(segments_.size(), num_threads, [&](std::size_t s) { stored[s] = SegmentHistograms(s); });
  std::vector<float> matrix(n * n, kInfinity);
  std::vector<absl::Status> errors(n);
  ParallelFor(n, num_threads, [&](std::size_t i) {
    const Location at = locations_.at(docs[i]);
    absl::StatusOr<PreparedQuery> q =
        Prepare(stored[at.segment][at.slot], absl::StrCat("model ", docs[i]));
    if (!q.ok()) {
      errors[i] = q.status();
      return;
    }
    float* row = &matrix[i * n];
    for (std::size_t s = 0; s < segments_.size(); ++s) {
      ScanSegment(*q, s, [&](uint32_t doc, float d) {
        auto it = column.find(doc);
        if (it != column.end()) row[it->second] = d;
      });
    }
    row[i] = 0.0f;
  });
  for (const absl::Status& error : errors) MESHSEEK_RETURN_IF_ERROR(error);
  return matrix;
}

std::size_t KlInvertedIndex::MemoryBytes() const {
  std::size_t bytes = sizeof(*this) + locations_.capacity() * (sizeof(uint32_t) + sizeof(Location) + 1);
  for (const auto& seg : segments_) {
    bytes += sizeof(Segment) + seg->postings.capacity() * sizeof(Segment::Postings);
    for (const Segment::Postings& p : seg->postings) {
      bytes += p.slots.capacity() * sizeof(uint16_t) + p.weights.capacity() * sizeof(float) +
               p.g.capacity() * sizeof(float);
    }
    bytes += seg->docs.capacity() * sizeof(uint32_t) + seg->live.capacity() + seg->empty.capacity() +
             (seg->c.capacity() + seg->e.capacity() + seg->a.capacity() + seg->big_g.capacity()) *
                 sizeof(double);
  }
  return bytes;
}

}  // namespace meshseek
