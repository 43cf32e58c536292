// The insides of KlInvertedIndex (kl_inverted_index.h) that its sources
// share: a prepared query, its dense form, and a segment (postings, forward
// offsets, value dictionary, per-slot constants). Included by
// kl_inverted_index.cc only; not an interface.
#ifndef MESHSEEK_COMMON_SEARCH_KL_INVERTED_INDEX_SEGMENT_H_
#define MESHSEEK_COMMON_SEARCH_KL_INVERTED_INDEX_SEGMENT_H_

#include <cstddef>
#include <cstdint>
#include <vector>

#include "absl/base/casts.h"
#include "absl/container/flat_hash_map.h"
#include "absl/status/status.h"
#include "absl/types/span.h"
#include "common/base/status_macros.h"
#include "common/search/forward_store.h"
#include "common/search/kl_inverted_index.h"

namespace meshseek {
namespace kl_internal {

// Distinct weights one segment can name with a 16-bit value id.
constexpr std::size_t kMaxValues = 1 << 16;

// Two doubles and two floats as GCC/Clang generic vectors: one SSE register
// and half of one at baseline x86-64 (NEON on aarch64). The scan adds both
// common sums of a posting with one packed multiply and add; each lane does
// exactly the scalar operation, so the sums are the same bits.
typedef double Double2 __attribute__((vector_size(16)));
typedef float Float2 __attribute__((vector_size(8)));

// The two common sums of one model against the query: lane 0 the query side
// a_xy = sum x_k g(y_k) (x the query), lane 1 the model side a_yx = sum y_k g(x_k).
using CommonSums = Double2;

// A forward entry: word in the high 16 bits, value id in the low.
inline uint32_t Entry(uint32_t word, uint16_t value) { return word << 16 | value; }
inline uint32_t WordOf(uint32_t entry) { return entry >> 16; }
inline uint16_t ValueIdOf(uint32_t entry) { return static_cast<uint16_t>(entry & 0xffff); }

}  // namespace kl_internal

struct KlInvertedIndex::PreparedQuery {
  std::vector<uint32_t> words;
  std::vector<float> weights;
  std::vector<float> g;  // float-rounded g(weight)
  double c = 0.0, e = 0.0, a = 0.0, big_g = 0.0;
  // sum_k sqrt(x_k) P[word_k], once the index has an embedding.
  std::vector<float> embedding;
  bool empty() const { return words.empty(); }
};

// A query as dense arrays, zero off its words, so that a model's forward
// entries are summed in word order with zero terms elsewhere: the same
// doubles as the postings' scan.
struct KlInvertedIndex::DenseQuery {
  explicit DenseQuery(const PreparedQuery& q, uint32_t vocabulary)
      : x(vocabulary, 0.0), g(vocabulary, 0.0) {
    for (std::size_t i = 0; i < q.words.size(); ++i) {
      x[q.words[i]] = q.weights[i];
      g[q.words[i]] = q.g[i];
    }
  }
  std::vector<double> x, g;
};

struct KlInvertedIndex::Segment {
  using CommonSums = kl_internal::CommonSums;
  using Double2 = kl_internal::Double2;
  using Float2 = kl_internal::Float2;
  // Per word, the postings of the segment's models: slot and value id.
  struct Postings {
    std::vector<uint16_t> slots;
    std::vector<uint16_t> values;
  };
  Segment(uint32_t vocabulary, bool with_postings) : postings(with_postings ? vocabulary : 0) {}

  bool has_postings() const { return !postings.empty(); }
  // Frees the postings: scans read the forward entries from here on.
  void DropPostings() { std::vector<Postings>().swap(postings); }

  // Value id of `weight` (with its g), added to the dictionary if new.
  uint16_t ValueOf(float weight, float g) {
    auto [it, inserted] =
        value_ids.try_emplace(absl::bit_cast<uint32_t>(weight), static_cast<uint16_t>(values.size()));
    if (inserted) values.push_back(Float2{g, weight});
    return it->second;
  }
  // Whether `q`'s weights fit the dictionary.
  bool Fits(const PreparedQuery& q) const {
    std::size_t fresh = 0;
    for (float w : q.weights) fresh += !value_ids.contains(absl::bit_cast<uint32_t>(w));
    return values.size() + fresh <= kl_internal::kMaxValues;
  }

  // Adds a model at the next slot: its forward entries (appended to
  // `forward`), postings where kept, constants. Unchanged but for new
  // dictionary values when the append fails.
  absl::Status Add(uint32_t doc, const PreparedQuery& q, ForwardStore* forward) {
    std::vector<uint32_t> entries(q.words.size());
    for (std::size_t i = 0; i < q.words.size(); ++i) {
      entries[i] = kl_internal::Entry(q.words[i], ValueOf(q.weights[i], q.g[i]));
    }
    MESHSEEK_ASSIGN_OR_RETURN(const uint64_t offset, forward->Append(entries));
    AddSlot(doc, offset, entries, q.empty(), q.c, q.e, q.a, q.big_g);
    return absl::OkStatus();
  }
  // The slot bookkeeping of Add, for entries already in the store (also
  // what compaction copies).
  void AddSlot(uint32_t doc, uint64_t offset, absl::Span<const uint32_t> entries, bool no_words,
               double c_, double e_, double a_, double big_g_) {
    const auto slot = static_cast<uint16_t>(docs.size());
    if (has_postings()) {
      for (uint32_t entry : entries) {
        Postings& p = postings[kl_internal::WordOf(entry)];
        p.slots.push_back(slot);
        p.values.push_back(kl_internal::ValueIdOf(entry));
      }
    }
    forward_offset.push_back(offset);
    forward_count.push_back(static_cast<uint32_t>(entries.size()));
    docs.push_back(doc);
    live.push_back(1);
    empty.push_back(no_words ? 1 : 0);
    c.push_back(c_);
    e.push_back(e_);
    a.push_back(a_);
    big_g.push_back(big_g_);
  }
  absl::Span<const uint32_t> Entries(std::size_t slot, const ForwardStore& forward,
                                     std::vector<uint32_t>* buffer) const {
    return forward.Read(forward_offset[slot], forward_count[slot], buffer);
  }
  // The histogram at `slot` (as given) with its prepared constants.
  PreparedQuery Stored(std::size_t slot, const ForwardStore& forward) const {
    PreparedQuery q;
    std::vector<uint32_t> buffer;
    for (uint32_t entry : Entries(slot, forward, &buffer)) {
      q.words.push_back(kl_internal::WordOf(entry));
      q.weights.push_back(values[kl_internal::ValueIdOf(entry)][1]);
      q.g.push_back(values[kl_internal::ValueIdOf(entry)][0]);
    }
    q.c = c[slot];
    q.e = e[slot];
    q.a = a[slot];
    q.big_g = big_g[slot];
    return q;
  }
  // The two common sums of the model at `slot` against a dense query.
  CommonSums ForwardSums(absl::Span<const uint32_t> entries, const DenseQuery& q) const {
    double query_side = 0.0, model_side = 0.0;
    for (uint32_t entry : entries) {
      const uint32_t word = kl_internal::WordOf(entry);
      const Float2 value = values[kl_internal::ValueIdOf(entry)];
      query_side += q.x[word] * static_cast<double>(value[0]);
      model_side += static_cast<double>(value[1]) * q.g[word];
    }
    return CommonSums{query_side, model_side};
  }

  // Adds the common sums of every slot that shares a word with the query,
  // from the postings of the query's words.
  void AccumulatePostings(const PreparedQuery& q, CommonSums* sum) const {
    const Float2* value = values.data();
    for (std::size_t i = 0; i < q.words.size(); ++i) {
      const Postings& p = postings[q.words[i]];
      // (x, g(x)) of the query word: lane 0 multiplies the model's g, lane 1
      // its weight. Both products of floats are exact in double.
      const Double2 factor{static_cast<double>(q.weights[i]), static_cast<double>(q.g[i])};
      const uint16_t* slots = p.slots.data();
      const uint16_t* ids = p.values.data();
      const std::size_t m = p.slots.size();
      std::size_t j = 0;
      for (; j + 4 <= m; j += 4) {  // four independent slots at a time
        const Double2 v0 = __builtin_convertvector(value[ids[j]], Double2) * factor;
        const Double2 v1 = __builtin_convertvector(value[ids[j + 1]], Double2) * factor;
        const Double2 v2 = __builtin_convertvector(value[ids[j + 2]], Double2) * factor;
        const Double2 v3 = __builtin_convertvector(value[ids[j + 3]], Double2) * factor;
        sum[slots[j]] += v0;
        sum[slots[j + 1]] += v1;
        sum[slots[j + 2]] += v2;
        sum[slots[j + 3]] += v3;
      }
      for (; j < m; ++j) sum[slots[j]] += __builtin_convertvector(value[ids[j]], Double2) * factor;
    }
  }

  std::vector<Postings> postings;  // per word; empty once dropped
  // Per slot, where its forward entries are in the index's ForwardStore.
  std::vector<uint64_t> forward_offset;
  std::vector<uint32_t> forward_count;
  // The value dictionary: per value id its float-rounded g and the weight,
  // side by side so that a posting loads both at once.
  std::vector<Float2> values;
  absl::flat_hash_map<uint32_t, uint16_t> value_ids;  // weight's bits -> id
  // Per slot.
  std::vector<uint32_t> docs;
  std::vector<uint8_t> live;
  std::vector<uint8_t> empty;  // no words: no local features
  std::vector<double> c, e, a, big_g;
  std::size_t dead = 0;
};

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_SEARCH_KL_INVERTED_INDEX_SEGMENT_H_
