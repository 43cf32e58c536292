// Synthetic bag-of-features histograms shaped like real ones, for the index
// benchmarks (index_benchmark through the service, search_benchmark in
// process).
//
// Each model draws `descriptors` words around a centre of its own,
// word = (centre + floor(V u^5.5)) mod V for uniform u: about 920 distinct
// words at V = 2,000 for 3,000 descriptors (real DLD-SIFT histograms of
// McGill use about 700, of PSB about half the words), about 1,600 at
// V = 20,000. Weights are counts over `descriptors`, as an encoder makes them.
#ifndef MESHSEEK_COMMON_SEARCH_SYNTHETIC_HISTOGRAMS_H_
#define MESHSEEK_COMMON_SEARCH_SYNTHETIC_HISTOGRAMS_H_

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "common/search/sparse_histogram.h"

namespace meshseek {

inline SparseHistogram SyntheticHistogram(std::mt19937_64& rng, int vocabulary, int descriptors) {
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  const uint32_t centre = static_cast<uint32_t>(rng() % vocabulary);
  std::vector<uint32_t> words(descriptors);
  for (uint32_t& w : words) {
    w = (centre + static_cast<uint32_t>(vocabulary * std::pow(uniform(rng), 5.5))) % vocabulary;
  }
  std::sort(words.begin(), words.end());
  SparseHistogram h;
  h.vocabulary = static_cast<uint32_t>(vocabulary);
  for (std::size_t i = 0; i < words.size();) {
    std::size_t j = i;
    while (j < words.size() && words[j] == words[i]) ++j;
    h.words.push_back(words[i]);
    h.weights.push_back(static_cast<float>(j - i) / static_cast<float>(descriptors));
    i = j;
  }
  return h;
}

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_SEARCH_SYNTHETIC_HISTOGRAMS_H_
