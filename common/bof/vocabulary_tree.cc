#include "common/bof/vocabulary_tree.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <numeric>
#include <utility>

#include "absl/strings/str_cat.h"
#include "common/base/logging.h"
#include "common/base/parallel.h"
#include "common/base/status_macros.h"

namespace meshseek {
namespace {

// Node i's k-means seed: the options' seed and i through SplitMix64's
// finaliser, so that sibling nodes draw unrelated samples.
uint64_t NodeSeed(uint64_t seed, uint32_t node) {
  uint64_t z = seed + 0x9e3779b97f4a7c15ULL * (static_cast<uint64_t>(node) + 1);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

// Shares `leaves` among children that received `points` each: one leaf each,
// then one at a time to the child furthest below its proportional share
// (lowest index on ties) among those with more points than leaves (a child
// with none keeps one leaf). The caller guarantees sum(points) >= leaves >=
// points.size().
std::vector<uint32_t> ShareLeaves(uint32_t leaves, const std::vector<std::size_t>& points) {
  const std::size_t total = std::accumulate(points.begin(), points.end(), std::size_t{0});
  std::vector<uint32_t> share(points.size(), 1);
  for (uint32_t given = static_cast<uint32_t>(points.size()); given < leaves; ++given) {
    std::size_t best = points.size();
    double best_deficit = 0;
    for (std::size_t c = 0; c < points.size(); ++c) {
      if (share[c] >= points[c]) continue;
      const double proportional =
          static_cast<double>(leaves) * static_cast<double>(points[c]) / static_cast<double>(total);
      const double deficit = proportional - share[c];
      if (best == points.size() || deficit > best_deficit) {
        best = c;
        best_deficit = deficit;
      }
    }
    ++share[best];
  }
  return share;
}

// The rows `rows` of `points` (dim bytes each), contiguous.
std::vector<uint8_t> Gather(const uint8_t* points,
                            std::size_t dim,
                            const std::vector<uint32_t>& rows) {
  std::vector<uint8_t> out(rows.size() * dim);
  for (std::size_t i = 0; i < rows.size(); ++i) {
    std::copy_n(points + static_cast<std::size_t>(rows[i]) * dim, dim, out.data() + i * dim);
  }
  return out;
}

// Each point's beam: up to `width` (score, node) pairs in increasing order,
// unused slots at +inf.
struct Beams {
  Beams(std::size_t count, std::size_t width)
      : width(width),
        score(count * width, std::numeric_limits<float>::infinity()),
        node(count * width, 0) {}
  void Clear() {
    std::fill(score.begin(), score.end(), std::numeric_limits<float>::infinity());
    std::fill(node.begin(), node.end(), 0u);
  }
  // Keeps the best `width` of point i's candidates: by score, then node.
  void Offer(std::size_t i, float s, uint32_t id) {
    float* b = &score[i * width];
    uint32_t* bn = &node[i * width];
    auto before = [&](std::size_t j) { return s < b[j] || (s == b[j] && id < bn[j]); };
    if (!before(width - 1)) return;
    std::size_t j = width - 1;
    for (; j > 0 && before(j - 1); --j) {
      b[j] = b[j - 1];
      bn[j] = bn[j - 1];
    }
    b[j] = s;
    bn[j] = id;
  }
  std::size_t width;
  std::vector<float> score;
  std::vector<uint32_t> node;
};

}  // namespace

absl::StatusOr<VocabularyTree> VocabularyTree::Train(const uint8_t* points,
                                                     std::size_t n,
                                                     std::size_t dim,
                                                     const KMeansOptions& options,
                                                     KMeansReport* report) {
  MESHSEEK_RETURN_IF_ERROR(options.Validate());
  const auto leaves = static_cast<uint32_t>(options.num_centroids);
  if (dim == 0) return absl::InvalidArgumentError("vocabulary tree: dim must be >= 1, got 0");
  if (n < leaves) {
    return absl::InvalidArgumentError(
        absl::StrCat("vocabulary tree: got ", n, " training points for ", leaves, " leaves"));
  }
  if (points == nullptr) return absl::InvalidArgumentError("vocabulary tree: points is null");
  // The sample sent in place of the set must be the one KMeansTrainingRows
  // draws from it, as TrainKMeans checks.
  const std::size_t max_train =
      static_cast<std::size_t>(leaves) * static_cast<std::size_t>(options.max_points_per_centroid);
  if (options.sampled_from > 0 && (options.sampled_from <= max_train || n != max_train)) {
    const uint64_t want = std::min<uint64_t>(options.sampled_from, max_train);
    return absl::InvalidArgumentError(absl::StrCat("vocabulary tree: ", n, " points sampled from ",
                                                   options.sampled_from, "; a sample of it has ",
                                                   want, " points"));
  }
  const absl::Time start = absl::Now();

  // The flat vocabulary's sample (kmeans.h step 1), made contiguous.
  std::vector<std::size_t> sample;
  if (options.sampled_from > 0) {
    sample.resize(n);
    std::iota(sample.begin(), sample.end(), std::size_t{0});
  } else {
    sample = KMeansTrainingRows(n, options);
  }
  const std::vector<uint8_t> train =
      Gather(points, dim, std::vector<uint32_t>(sample.begin(), sample.end()));

  VocabularyTree tree;
  tree.dim_ = dim;
  tree.probes_ = static_cast<uint32_t>(options.tree_probes);
  MESHSEEK_RETURN_IF_ERROR(tree.Grow(train, options));
  const std::vector<double> objective = tree.Refine(train, kRefinements, options.num_threads);
  if (report != nullptr) {
    *report = KMeansReport();
    report->input_points = n;
    report->training_points = sample.size();
    report->iterations = kRefinements;
    report->objective = objective;
  }
  MESHSEEK_LOG(INFO) << "vocabulary tree: " << tree.num_leaves() << " leaves, depth "
                     << tree.depth() << ", " << tree.nodes_.size() << " nodes, " << tree.probes_
                     << " probes, from " << sample.size() << " of " << n
                     << " points, mean squared distance " << objective.front() << " grown, "
                     << objective.back() << " refined, "
                     << absl::FormatDuration(
                            absl::Trunc(absl::Now() - start, absl::Milliseconds(1)));
  return tree;
}

absl::Status VocabularyTree::Grow(const std::vector<uint8_t>& train, const KMeansOptions& options) {
  const std::size_t dim = dim_;
  struct Pending {
    uint32_t node;
    std::vector<uint32_t> rows;  // into train
    uint32_t leaves;
    int levels;
  };
  std::deque<Pending> pending;
  std::vector<uint32_t> all_rows(train.size() / dim);
  std::iota(all_rows.begin(), all_rows.end(), 0u);
  nodes_.assign(1, Node());
  pending.push_back(
      {0, std::move(all_rows), static_cast<uint32_t>(options.num_centroids), options.tree_depth});
  while (!pending.empty()) {
    Pending at = std::move(pending.front());
    pending.pop_front();
    if (at.leaves == 1 || at.levels == 0) continue;  // a leaf
    uint32_t k = at.levels == 1 ? at.leaves
                                : static_cast<uint32_t>(std::lround(
                                      std::pow(static_cast<double>(at.leaves), 1.0 / at.levels)));
    k = std::clamp<uint32_t>(k, 2, at.leaves);
    const std::vector<uint8_t> node_points = Gather(train.data(), dim, at.rows);
    KMeansOptions node = options;
    node.num_centroids = static_cast<int>(k);
    node.assignment = KMeansOptions::Assignment::kExact;
    node.seeding = KMeansOptions::Seeding::kAuto;
    node.sampled_from = 0;
    node.seed = NodeSeed(options.seed, at.node);
    node.min_points_per_centroid = 1;
    // The last level trains on all its points: its centres are words.
    const int all_points = static_cast<int>((at.rows.size() + k - 1) / k);
    node.max_points_per_centroid =
        std::max(1, at.levels == 1 ? all_points : kNodePointsPerCentroid);
    MESHSEEK_ASSIGN_OR_RETURN(
        std::vector<float> centres,
        internal::TrainKMeansQuietly(node_points.data(), at.rows.size(), dim, node, nullptr));
    // Every point of the node to its nearest child: the descent.
    std::vector<uint32_t> labels(at.rows.size());
    NearestCentroidIndex(centres.data(), k, dim)
        .Search(node_points.data(), at.rows.size(), options.num_threads, labels.data(), nullptr);
    std::vector<std::vector<uint32_t>> child_rows(k);
    for (std::size_t i = 0; i < labels.size(); ++i) child_rows[labels[i]].push_back(at.rows[i]);
    std::vector<std::size_t> counts(k);
    for (uint32_t c = 0; c < k; ++c) counts[c] = child_rows[c].size();
    const std::vector<uint32_t> share = ShareLeaves(at.leaves, counts);

    const auto first = static_cast<uint32_t>(nodes_.size());
    nodes_[at.node].first_child = first;
    nodes_[at.node].num_children = k;
    nodes_.resize(first + k);
    centres_.insert(centres_.end(), centres.begin(), centres.end());
    for (uint32_t c = 0; c < k; ++c) {
      pending.push_back({first + c, std::move(child_rows[c]), share[c], at.levels - 1});
    }
  }
  uint32_t leaf = 0;
  for (Node& node : nodes_) {
    if (node.num_children == 0) node.leaf = leaf++;
  }
  Index();
  return absl::OkStatus();
}

std::vector<double> VocabularyTree::Refine(const std::vector<uint8_t>& train,
                                           int iterations,
                                           int num_threads) {
  const std::size_t dim = dim_;
  const std::size_t n = train.size() / dim;
  std::vector<uint32_t> labels(n);
  std::vector<float> distances(n);
  std::vector<double> objective;
  for (int it = 0;; ++it) {
    Search(train.data(), n, num_threads, labels.data(), distances.data());
    double sum = 0;
    for (float d : distances) sum += d;
    objective.push_back(sum / static_cast<double>(n));
    if (it == iterations) return objective;
    // Each leaf's centre to the mean of its points (sums in point order, in
    // double: the same for any thread count); a leaf without points stays.
    std::vector<double> sums(num_leaves() * dim, 0.0);
    std::vector<std::size_t> counts(num_leaves(), 0);
    for (std::size_t i = 0; i < n; ++i) {
      ++counts[labels[i]];
      double* s = &sums[labels[i] * dim];
      for (std::size_t j = 0; j < dim; ++j) s[j] += train[i * dim + j];
    }
    for (std::size_t w = 0; w < num_leaves(); ++w) {
      if (counts[w] == 0) continue;
      float* centre = &centres_[(leaf_node_[w] - 1) * dim];
      for (std::size_t j = 0; j < dim; ++j) {
        centre[j] = static_cast<float>(sums[w * dim + j] / static_cast<double>(counts[w]));
      }
    }
    Index();
  }
}

absl::StatusOr<VocabularyTree> VocabularyTree::FromNodes(std::vector<Node> nodes,
                                                         std::vector<float> centres,
                                                         std::size_t dim,
                                                         uint32_t probes) {
  auto bad = [](auto&&... parts) {
    return absl::InvalidArgumentError(absl::StrCat("vocabulary tree: ", parts...));
  };
  if (dim == 0) return bad("dim must be >= 1");
  if (probes < 1 || probes > kMaxProbes) return bad(probes, " probes (want 1 to ", kMaxProbes, ")");
  if (nodes.empty() || nodes.size() >= (uint64_t{1} << 32)) {
    return bad(nodes.size(), " nodes (want 1 to 2^32 - 1)");
  }
  if (centres.size() != (nodes.size() - 1) * dim) {
    return bad(centres.size(), " centre values for ", nodes.size(), " nodes of dimension ", dim);
  }
  for (std::size_t i = 0; i < centres.size(); ++i) {
    if (!std::isfinite(centres[i])) return bad("centre value ", i, " is not finite");
  }
  // Breadth first: the child ranges, in node order, tile 1..N-1.
  std::size_t next_child = 1;
  std::size_t num_leaves = 0;
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    const Node& node = nodes[i];
    if (node.num_children == 0) {
      ++num_leaves;
      continue;
    }
    if (node.first_child != next_child || node.first_child <= i ||
        node.num_children > nodes.size() - node.first_child) {
      return bad("node ", i, "'s children [", node.first_child, ", +", node.num_children,
                 ") do not follow the nodes before them");
    }
    next_child += node.num_children;
  }
  if (next_child != nodes.size()) return bad("nodes ", next_child, ".. have no parent");
  if (nodes[0].num_children == 0) return bad("the root has no children");
  std::vector<bool> seen(num_leaves, false);
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    if (nodes[i].num_children != 0) continue;
    if (nodes[i].leaf >= num_leaves || seen[nodes[i].leaf]) {
      return bad("leaf node ", i, " has word ", nodes[i].leaf, ", repeated or not below ",
                 num_leaves);
    }
    seen[nodes[i].leaf] = true;
  }
  VocabularyTree tree;
  tree.dim_ = dim;
  tree.probes_ = probes;
  tree.nodes_ = std::move(nodes);
  tree.centres_ = std::move(centres);
  tree.Index();
  return tree;
}

void VocabularyTree::Index() {
  children_.assign(nodes_.size(), NearestCentroidIndex());
  std::vector<int> level(nodes_.size(), 0);
  const auto is_leaf = [](const Node& n) { return n.num_children == 0; };
  leaf_node_.assign(std::count_if(nodes_.begin(), nodes_.end(), is_leaf), 0);
  depth_ = 0;
  for (std::size_t i = 0; i < nodes_.size(); ++i) {
    const Node& node = nodes_[i];
    if (node.num_children == 0) {
      leaf_node_[node.leaf] = static_cast<uint32_t>(i);
      depth_ = std::max(depth_, level[i]);
      continue;
    }
    children_[i] = NearestCentroidIndex(&centres_[(node.first_child - 1) * dim_],
                                        node.num_children, dim_);
    for (uint32_t c = 0; c < node.num_children; ++c) level[node.first_child + c] = level[i] + 1;
  }
}

std::vector<float> VocabularyTree::LeafCentres() const {
  std::vector<float> out(num_leaves() * dim_);
  for (std::size_t w = 0; w < num_leaves(); ++w) {
    std::copy_n(&centres_[(leaf_node_[w] - 1) * dim_], dim_, &out[w * dim_]);
  }
  return out;
}

void VocabularyTree::Search(const uint8_t* points,
                            std::size_t n,
                            int num_threads,
                            uint32_t* labels,
                            float* squared_distances) const {
  const std::size_t num_blocks = (n + kPointsPerBlock - 1) / kPointsPerBlock;
  ParallelFor(num_blocks, num_threads, [&](std::size_t block) {
    const std::size_t begin = block * kPointsPerBlock;
    SearchBlock(points + begin * dim_, std::min(kPointsPerBlock, n - begin), labels + begin,
                squared_distances == nullptr ? nullptr : squared_distances + begin);
  });
}

void VocabularyTree::SearchBlock(const uint8_t* points,
                                 std::size_t count,
                                 uint32_t* labels,
                                 float* squared_distances) const {
  const std::size_t dim = dim_;
  const std::size_t beam = probes_;
  std::vector<float> x(count * dim);
  for (std::size_t i = 0; i < count * dim; ++i) x[i] = static_cast<float>(points[i]);
  // Scores are ||c||^2 - 2 x.c of a node's centre: comparable across nodes
  // for one point (nearest_centroid.h). The beams start at the root.
  constexpr float kInf = std::numeric_limits<float>::infinity();
  Beams beams(count, beam), next(count, beam);
  for (std::size_t i = 0; i < count; ++i) beams.score[i * beam] = 0.0f;
  std::vector<float>& score = beams.score;
  std::vector<uint32_t>& node = beams.node;
  std::vector<uint32_t> offsets(nodes_.size() + 1), bucket, local;
  std::vector<float> batch, local_score;
  for (int pass = 0; pass < depth_; ++pass) {
    next.Clear();
    // Only the best of the last level is kept (labels and distances read
    // entry 0 of each beam), and the beams' order is total (score, then
    // node): each node's own best alone gives the same winner, with a
    // fraction of the top-k insertions, which cost more than the distances.
    const bool last = pass + 1 == depth_;
    // Leaves stay in the beam; internal nodes are bucketed (counting sort)
    // so that each searches its points' block at once.
    std::fill(offsets.begin(), offsets.end(), 0u);
    for (std::size_t e = 0; e < count * beam; ++e) {
      if (score[e] == kInf) continue;
      if (nodes_[node[e]].num_children == 0) {
        next.Offer(e / beam, score[e], node[e]);
      } else {
        ++offsets[node[e] + 1];
      }
    }
    std::partial_sum(offsets.begin(), offsets.end(), offsets.begin());
    bucket.resize(offsets.back());
    {
      std::vector<uint32_t> fill(offsets.begin(), offsets.end() - 1);
      for (std::size_t e = 0; e < count * beam; ++e) {
        if (score[e] != kInf && nodes_[node[e]].num_children > 0) {
          bucket[fill[node[e]]++] = static_cast<uint32_t>(e / beam);
        }
      }
    }
    for (std::size_t id = 0; id < nodes_.size(); ++id) {
      const std::size_t m = offsets[id + 1] - offsets[id];
      if (m == 0) continue;
      const Node& at = nodes_[id];
      const std::size_t k = last ? 1 : std::min<std::size_t>(beam, at.num_children);
      batch.resize(m * dim);
      for (std::size_t j = 0; j < m; ++j) {
        std::copy_n(&x[bucket[offsets[id] + j] * dim], dim, &batch[j * dim]);
      }
      local.resize(m * k);
      local_score.resize(m * k);
      children_[id].SearchTopK(batch.data(), m, k, local.data(), local_score.data());
      for (std::size_t j = 0; j < m; ++j) {
        for (std::size_t c = 0; c < k; ++c) {
          next.Offer(bucket[offsets[id] + j], local_score[j * k + c],
                     at.first_child + local[j * k + c]);
        }
      }
    }
    score.swap(next.score);
    node.swap(next.node);
  }
  for (std::size_t i = 0; i < count; ++i) {
    labels[i] = nodes_[node[i * beam]].leaf;
    if (squared_distances == nullptr) continue;
    // As NearestCentroidIndex::Search: ||x||^2 in double, plus the score.
    double norm = 0.0;
    for (std::size_t d = 0; d < dim; ++d) {
      norm += static_cast<double>(x[i * dim + d]) * x[i * dim + d];
    }
    squared_distances[i] = std::max(0.0f, static_cast<float>(norm) + score[i * beam]);
  }
}

}  // namespace meshseek
