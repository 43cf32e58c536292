#include "common/search/kl_inverted_index.h"

#include <malloc.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <tuple>
#include <utility>

#include "absl/base/casts.h"
#include "absl/strings/str_cat.h"
#include "common/base/parallel.h"
#include "common/base/status_macros.h"
#include "common/search/forward_store.h"
#include "common/search/kl_inverted_index_segment.h"

namespace meshseek {

using kl_internal::CommonSums;
using kl_internal::Double2;
using kl_internal::Float2;

namespace {

constexpr float kInfinity = std::numeric_limits<float>::infinity();
// Scratch of one thread: the common sums of a segment's slots.
std::vector<CommonSums>& Scratch() {
  thread_local std::vector<CommonSums> scratch;
  return scratch;
}

// The embedding's fixed seed: its axes are a function of the sample alone.
constexpr uint64_t kEmbeddingSeed = 0x6d657368u;  // "mesh"

// Hands the heap's free pages back to the system after a large transient
// allocation (the embedding's fit, freed postings): glibc keeps them in its
// arenas otherwise, and a service's resident memory would stay at its peak.
void ReturnFreedMemory() {
#ifdef __GLIBC__
  malloc_trim(0);
#endif
}

bool Closer(const KlNeighbor& a, const KlNeighbor& b) {
  return a.distance < b.distance || (a.distance == b.distance && a.doc < b.doc);
}

}  // namespace

absl::Status KlIndexStorage::Check() const {
  if (postings_max_models == 0) {
    return absl::InvalidArgumentError("KlIndexStorage: postings_max_models must be at least 1");
  }
  return absl::OkStatus();
}

KlInvertedIndex::KlInvertedIndex(uint32_t vocabulary,
                                 const KlDivergenceOptions& options,
                                 const KlIndexStorage& storage,
                                 std::unique_ptr<ForwardStore> forward)
    : vocabulary_(vocabulary), options_(options), storage_(storage), forward_(std::move(forward)) {}
KlInvertedIndex::KlInvertedIndex(KlInvertedIndex&&) noexcept = default;
KlInvertedIndex& KlInvertedIndex::operator=(KlInvertedIndex&&) noexcept = default;
KlInvertedIndex::~KlInvertedIndex() = default;

absl::StatusOr<KlInvertedIndex> KlInvertedIndex::Create(uint32_t vocabulary,
                                                        const KlDivergenceOptions& options,
                                                        const KlIndexStorage& storage) {
  MESHSEEK_RETURN_IF_ERROR(options.Validate());
  MESHSEEK_RETURN_IF_ERROR(storage.Check());
  if (vocabulary == 0 || vocabulary > kMaxVocabulary) {
    return absl::InvalidArgumentError(absl::StrCat("KlInvertedIndex: vocabulary ", vocabulary,
                                                   " is not in [1, ", kMaxVocabulary, "]"));
  }
  std::unique_ptr<ForwardStore> forward = ForwardStore::InMemory();
  if (!storage.forward_dir.empty()) {
    MESHSEEK_ASSIGN_OR_RETURN(forward, ForwardStore::InFile(storage.forward_dir));
  }
  return KlInvertedIndex(vocabulary, options, storage, std::move(forward));
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
  if (embedding_) Embed(&q);
  q.c = 1.0 / (sum + vocabulary_ * eps);
  q.e = eps * q.c;
  return q;
}

absl::Status KlInvertedIndex::Append(uint32_t doc, const PreparedQuery& q) {
  if (segments_.empty() || segments_.back()->docs.size() == kSegmentSlots ||
      !segments_.back()->Fits(q)) {
    segments_.push_back(std::make_unique<Segment>(vocabulary_, postings_));
  }
  Segment& seg = *segments_.back();
  const Location at{static_cast<uint32_t>(segments_.size() - 1),
                    static_cast<uint16_t>(seg.docs.size())};
  MESHSEEK_RETURN_IF_ERROR(seg.Add(doc, q, forward_.get()));
  locations_[doc] = at;
  live_entries_ += q.words.size();
  if (postings_ && size() > storage_.postings_max_models) {
    // Large: scans read the forward entries (see "Storage" in the header).
    postings_ = false;
    for (const auto& segment : segments_) segment->DropPostings();
    ReturnFreedMemory();
  }
  // Models without words have no distance to anything: never proposed.
  if (candidates_.has_value() && !q.empty()) candidates_->Add(doc, q.embedding);
  if (!embedding_ && size() >= kEmbeddingFitModels) FitEmbedding();
  return absl::OkStatus();
}

void KlInvertedIndex::Embed(PreparedQuery* q) const {
  q->embedding.resize(kEmbeddingDimensions);
  embedding_->Embed(q->words, q->weights, q->embedding.data());
}

void KlInvertedIndex::FitEmbedding() {
  // The sample: every live model, in segment and slot order (insertion
  // order, up to compactions).
  std::vector<SparseHistogram> sample;
  sample.reserve(size());
  ForEach([&](uint32_t, const SparseHistogram& h) { sample.push_back(h); });
  absl::StatusOr<HistogramEmbedding> fitted = HistogramEmbedding::Fit(
      sample, vocabulary_, static_cast<int>(kEmbeddingDimensions), kEmbeddingSeed);
  if (!fitted.ok()) return;  // cannot happen for stored (valid) histograms: stay exact
  embedding_ = *std::move(fitted);
  candidates_ = *CandidateIndex::Create(static_cast<int>(kEmbeddingDimensions));
  for (const auto& seg : segments_) {
    for (std::size_t slot = 0; slot < seg->docs.size(); ++slot) {
      if (!seg->live[slot] || seg->empty[slot]) continue;
      PreparedQuery q = seg->Stored(slot, *forward_);
      Embed(&q);
      candidates_->Add(seg->docs[slot], q.embedding);
    }
  }
  ReturnFreedMemory();  // the fit's sample and work matrices: ~0.5 GB at V = 40,000
}

absl::Status KlInvertedIndex::Upsert(uint32_t doc, const SparseHistogram& histogram) {
  MESHSEEK_ASSIGN_OR_RETURN(const PreparedQuery prepared,
                            Prepare(histogram, absl::StrCat("model ", doc)));
  // The new copy first: a failed append leaves the old one in place.
  const auto old = locations_.find(doc);
  const std::optional<Location> was =
      old != locations_.end() ? std::optional<Location>(old->second) : std::nullopt;
  MESHSEEK_RETURN_IF_ERROR(Append(doc, prepared));
  if (was.has_value()) RemoveSlot(*was);
  return absl::OkStatus();
}

bool KlInvertedIndex::Remove(uint32_t doc) {
  auto it = locations_.find(doc);
  if (it == locations_.end()) return false;
  const Location at = it->second;
  locations_.erase(it);
  if (candidates_.has_value()) candidates_->Remove(doc);
  RemoveSlot(at);
  return true;
}

void KlInvertedIndex::RemoveSlot(Location at) {
  Segment& seg = *segments_[at.segment];
  seg.live[at.slot] = 0;
  ++seg.dead;
  live_entries_ -= seg.forward_count[at.slot];
  if (seg.dead * 2 > seg.docs.size()) CompactSegment(at.segment);
  // Entries of dead models outnumber the live ones: rewrite the store.
  if (forward_->size() > 2 * live_entries_ + (1u << 20)) RewriteForward();
}

void KlInvertedIndex::CompactSegment(std::size_t s) {
  // Rebuilds segment s from its live slots, in slot order: slots change,
  // docs, values and forward entries do not (the dictionary is kept). The
  // rebuilt segment replaces s in place.
  const Segment& old = *segments_[s];
  auto rebuilt = std::make_unique<Segment>(vocabulary_, old.has_postings());
  rebuilt->values = old.values;
  rebuilt->value_ids = old.value_ids;
  std::vector<uint32_t> buffer;
  for (std::size_t slot = 0; slot < old.docs.size(); ++slot) {
    if (!old.live[slot]) continue;
    locations_[old.docs[slot]] =
        Location{static_cast<uint32_t>(s), static_cast<uint16_t>(rebuilt->docs.size())};
    rebuilt->AddSlot(old.docs[slot], old.forward_offset[slot], old.Entries(slot, *forward_, &buffer),
                     old.empty[slot], old.c[slot], old.e[slot], old.a[slot], old.big_g[slot]);
  }
  segments_[s] = std::move(rebuilt);
}

void KlInvertedIndex::RewriteForward() {
  // The live slots' entries into a new store of the same kind, in segment
  // and slot order; on a write error the old store stays (it is whole).
  std::unique_ptr<ForwardStore> fresh = ForwardStore::InMemory();
  if (forward_->in_file()) {
    absl::StatusOr<std::unique_ptr<ForwardStore>> file = ForwardStore::InFile(storage_.forward_dir);
    if (!file.ok()) return;
    fresh = *std::move(file);
  }
  std::vector<std::vector<uint64_t>> offsets(segments_.size());
  std::vector<uint32_t> buffer;
  for (std::size_t s = 0; s < segments_.size(); ++s) {
    const Segment& seg = *segments_[s];
    offsets[s].assign(seg.docs.size(), 0);
    for (std::size_t slot = 0; slot < seg.docs.size(); ++slot) {
      if (!seg.live[slot]) continue;
      absl::StatusOr<uint64_t> at = fresh->Append(seg.Entries(slot, *forward_, &buffer));
      if (!at.ok()) return;
      offsets[s][slot] = *at;
    }
  }
  for (std::size_t s = 0; s < segments_.size(); ++s) {
    Segment& seg = *segments_[s];
    for (std::size_t slot = 0; slot < seg.docs.size(); ++slot) {
      seg.forward_offset[slot] = offsets[s][slot];
      if (!seg.live[slot]) seg.forward_count[slot] = 0;
    }
  }
  forward_ = std::move(fresh);
}

namespace {

SparseHistogram ToHistogram(uint32_t vocabulary, std::vector<uint32_t> words,
                            std::vector<float> weights) {
  SparseHistogram h;
  h.vocabulary = vocabulary;
  h.words = std::move(words);
  h.weights = std::move(weights);
  return h;
}

}  // namespace

void KlInvertedIndex::ForEach(
    const std::function<void(uint32_t, const SparseHistogram&)>& fn) const {
  for (const auto& seg : segments_) {
    for (std::size_t slot = 0; slot < seg->docs.size(); ++slot) {
      if (!seg->live[slot]) continue;
      PreparedQuery q = seg->Stored(slot, *forward_);
      fn(seg->docs[slot], ToHistogram(vocabulary_, std::move(q.words), std::move(q.weights)));
    }
  }
}

absl::StatusOr<SparseHistogram> KlInvertedIndex::Histogram(uint32_t doc) const {
  auto it = locations_.find(doc);
  if (it == locations_.end()) {
    return absl::NotFoundError(absl::StrCat("model ", doc, " is not in the index"));
  }
  PreparedQuery q = segments_[it->second.segment]->Stored(it->second.slot, *forward_);
  return ToHistogram(vocabulary_, std::move(q.words), std::move(q.weights));
}

double KlInvertedIndex::Combine(const PreparedQuery& q,
                                const Segment& seg,
                                std::size_t slot,
                                double query_side,
                                double model_side) {
  return q.c * (q.a - query_side) + seg.c[slot] * (seg.a[slot] - model_side) +
         (q.e - seg.e[slot]) * (q.big_g - seg.big_g[slot]);
}

template <typename Emit>
void KlInvertedIndex::ScanSegment(const PreparedQuery& q,
                                  const DenseQuery* dense,
                                  std::size_t s,
                                  Emit&& emit) const {
  const Segment& seg = *segments_[s];
  const std::size_t n = seg.docs.size();
  if (q.empty()) {
    for (std::size_t slot = 0; slot < n; ++slot) {
      if (seg.live[slot]) emit(seg.docs[slot], kInfinity);
    }
    return;
  }
  std::vector<CommonSums>& sums = Scratch();
  sums.assign(n, CommonSums{0.0, 0.0});
  if (!seg.has_postings()) {
    // Every live model's forward entries against the dense query: the same
    // doubles, O(the segment's entries) instead of O(the query's postings).
    std::vector<uint32_t> buffer;
    for (std::size_t slot = 0; slot < n; ++slot) {
      if (seg.live[slot] && !seg.empty[slot]) {
        sums[slot] = seg.ForwardSums(seg.Entries(slot, *forward_, &buffer), *dense);
      }
    }
  } else {
    seg.AccumulatePostings(q, sums.data());
  }
  for (std::size_t slot = 0; slot < n; ++slot) {
    if (!seg.live[slot]) continue;
    if (seg.empty[slot]) {
      emit(seg.docs[slot], kInfinity);
      continue;
    }
    const double d = Combine(q, seg, slot, sums[slot][0], sums[slot][1]);
    emit(seg.docs[slot], d > 0.0 ? static_cast<float>(d) : 0.0f);
  }
}

absl::StatusOr<std::vector<KlNeighbor>> KlInvertedIndex::Distances(const SparseHistogram& query,
                                                                   int num_threads) const {
  MESHSEEK_ASSIGN_OR_RETURN(const PreparedQuery q, Prepare(query, "query"));
  return AllDistances(q, num_threads);
}

std::vector<KlNeighbor> KlInvertedIndex::AllDistances(const PreparedQuery& q,
                                                      int num_threads) const {
  // Each segment writes its own range of the output: segment s starts after
  // the live models of segments before it.
  std::vector<std::size_t> offsets(segments_.size() + 1, 0);
  for (std::size_t s = 0; s < segments_.size(); ++s) {
    offsets[s + 1] = offsets[s] + segments_[s]->docs.size() - segments_[s]->dead;
  }
  std::vector<KlNeighbor> out(offsets.back());
  const std::optional<DenseQuery> dense =
      postings_ ? std::nullopt : std::optional<DenseQuery>(DenseQuery(q, vocabulary_));
  ParallelFor(segments_.size(), num_threads, [&](std::size_t s) {
    std::size_t at = offsets[s];
    ScanSegment(q, dense ? &*dense : nullptr, s,
                [&](uint32_t doc, float d) { out[at++] = KlNeighbor{doc, d}; });
  });
  return out;
}

std::vector<KlNeighbor> KlInvertedIndex::RerankCandidates(const PreparedQuery& q,
                                                          std::size_t candidates,
                                                          int num_threads) const {
  // The candidate index's proposals (live, with words), then their exact
  // distances from the forward index.
  const std::vector<Candidate> proposed = candidates_->Nearest(q.embedding, candidates);
  std::vector<Location> at(proposed.size());
  for (std::size_t c = 0; c < proposed.size(); ++c) at[c] = locations_.at(proposed[c].doc);
  return ForwardDistances(q, at, num_threads);
}

std::vector<KlNeighbor> KlInvertedIndex::ForwardDistances(const PreparedQuery& q,
                                                          const std::vector<Location>& at,
                                                          int num_threads) const {
  const DenseQuery dense(q, vocabulary_);  // read-only from here: the threads share it
  std::vector<KlNeighbor> out(at.size());
  constexpr std::size_t kPerTask = 256;
  ParallelFor((at.size() + kPerTask - 1) / kPerTask, num_threads, [&](std::size_t task) {
    std::vector<uint32_t> buffer;
    const std::size_t end = std::min(at.size(), (task + 1) * kPerTask);
    for (std::size_t c = task * kPerTask; c < end; ++c) {
      const Segment& seg = *segments_[at[c].segment];
      const uint16_t slot = at[c].slot;
      if (q.empty() || seg.empty[slot]) {  // the scan's rule for models without words
        out[c] = {seg.docs[slot], kInfinity};
        continue;
      }
      const CommonSums sums = seg.ForwardSums(seg.Entries(slot, *forward_, &buffer), dense);
      const double distance = Combine(q, seg, slot, sums[0], sums[1]);
      out[c] = {seg.docs[slot], distance > 0.0 ? static_cast<float>(distance) : 0.0f};
    }
  });
  return out;
}

absl::StatusOr<std::vector<KlNeighbor>> KlInvertedIndex::DistancesTo(
    const SparseHistogram& query, absl::Span<const uint32_t> docs, int num_threads) const {
  MESHSEEK_ASSIGN_OR_RETURN(const PreparedQuery q, Prepare(query, "query"));
  return DistancesTo(q, docs, num_threads);
}

absl::StatusOr<std::vector<KlNeighbor>> KlInvertedIndex::DistancesFromStored(
    uint32_t doc, absl::Span<const uint32_t> docs, int num_threads) const {
  MESHSEEK_ASSIGN_OR_RETURN(const PreparedQuery q, StoredQuery(doc, /*embedded=*/false));
  return DistancesTo(q, docs, num_threads);
}

absl::StatusOr<std::vector<KlNeighbor>> KlInvertedIndex::DistancesTo(
    const PreparedQuery& q, absl::Span<const uint32_t> docs, int num_threads) const {
  std::vector<Location> at(docs.size());
  for (std::size_t i = 0; i < docs.size(); ++i) {
    const auto it = locations_.find(docs[i]);
    if (it == locations_.end()) {
      return absl::NotFoundError(absl::StrCat("distances: model ", docs[i], " is not stored"));
    }
    at[i] = it->second;
  }
  return ForwardDistances(q, at, num_threads);
}

absl::StatusOr<std::vector<KlNeighbor>> KlInvertedIndex::Search(const SparseHistogram& query,
                                                                std::size_t k,
                                                                int num_threads,
                                                                std::size_t candidates) const {
  if (k == 0) return absl::InvalidArgumentError("search: k must be at least 1");
  MESHSEEK_ASSIGN_OR_RETURN(const PreparedQuery q, Prepare(query, "query"));
  return Search(q, k, num_threads, candidates);
}

absl::StatusOr<std::vector<KlNeighbor>> KlInvertedIndex::SearchStored(uint32_t doc,
                                                                      std::size_t k,
                                                                      int num_threads,
                                                                      std::size_t candidates) const {
  if (k == 0) return absl::InvalidArgumentError("search: k must be at least 1");
  MESHSEEK_ASSIGN_OR_RETURN(const PreparedQuery q, StoredQuery(doc, /*embedded=*/true));
  return Search(q, k, num_threads, candidates);
}

absl::StatusOr<KlInvertedIndex::PreparedQuery> KlInvertedIndex::StoredQuery(uint32_t doc,
                                                                            bool embedded) const {
  const auto it = locations_.find(doc);
  if (it == locations_.end()) {
    return absl::NotFoundError(absl::StrCat("model ", doc, " is not in the index"));
  }
  PreparedQuery q = segments_[it->second.segment]->Stored(it->second.slot, *forward_);
  // The embedding the candidate index holds is the one Prepare computes.
  if (embedded && candidates_.has_value() && !q.empty()) {
    MESHSEEK_ASSIGN_OR_RETURN(q.embedding, candidates_->Vector(doc));
  }
  return q;
}

std::vector<KlNeighbor> KlInvertedIndex::Search(const PreparedQuery& q,
                                                std::size_t k,
                                                int num_threads,
                                                std::size_t candidates) const {
  // Candidates only when they are fewer than the models and the query can
  // have finite distances; otherwise the exact scan is the answer.
  std::vector<KlNeighbor> all = candidates > 0 && candidates >= k && candidates < size() &&
                                        candidates_.has_value() && !q.empty()
                                    ? RerankCandidates(q, candidates, num_threads)
                                    : AllDistances(q, num_threads);
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
  std::vector<float> matrix(n * n, kInfinity);
  ParallelFor(n, num_threads, [&](std::size_t i) {
    const Location at = locations_.at(docs[i]);
    const PreparedQuery q = segments_[at.segment]->Stored(at.slot, *forward_);
    const std::optional<DenseQuery> dense =
        postings_ ? std::nullopt : std::optional<DenseQuery>(DenseQuery(q, vocabulary_));
    float* row = &matrix[i * n];
    for (std::size_t s = 0; s < segments_.size(); ++s) {
      ScanSegment(q, dense ? &*dense : nullptr, s, [&](uint32_t doc, float d) {
        auto it = column.find(doc);
        if (it != column.end()) row[it->second] = d;
      });
    }
    row[i] = 0.0f;
  });
  return matrix;
}

uint64_t KlInvertedIndex::FileBytes() const { return forward_->FileBytes(); }

std::size_t KlInvertedIndex::MemoryBytes() const {
  std::size_t bytes = sizeof(*this) +
                      (embedding_ ? vocabulary_ * kEmbeddingDimensions * sizeof(float) : 0) +
                      (candidates_.has_value() ? candidates_->MemoryBytes() : 0) +
                      forward_->MemoryBytes() +
                      locations_.capacity() * (sizeof(uint32_t) + sizeof(Location) + 1);
  for (const auto& seg : segments_) {
    bytes += sizeof(Segment) + seg->postings.capacity() * sizeof(Segment::Postings) +
             seg->forward_offset.capacity() * sizeof(uint64_t) +
             seg->forward_count.capacity() * sizeof(uint32_t);
    for (const Segment::Postings& p : seg->postings) {
      bytes += (p.slots.capacity() + p.values.capacity()) * sizeof(uint16_t);
    }
    bytes += seg->values.capacity() * sizeof(Float2) +
             seg->value_ids.capacity() * (sizeof(uint32_t) + sizeof(uint16_t) + 1);
    bytes += seg->docs.capacity() * sizeof(uint32_t) + seg->live.capacity() + seg->empty.capacity() +
             (seg->c.capacity() + seg->e.capacity() + seg->a.capacity() + seg->big_g.capacity()) *
                 sizeof(double);
  }
  return bytes;
}

}  // namespace meshseek
