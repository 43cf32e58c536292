#include "common/bof/vocabulary_tree.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <numeric>
#include <utility>

#include "absl/strings/str_cat.h"
#include "common/base/logging.h"
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
  const absl::Time start = absl::Now();

  // The flat vocabulary's sample (kmeans.h step 1), made contiguous.
  std::vector<std::size_t> sample;
  if (options.sampled_from > 0) {
    sample.resize(n);
    std::iota(sample.begin(), sample.end(), std::size_t{0});
  } else {
    sample = KMeansTrainingRows(n, options);
  }
  std::vector<uint32_t> all_rows(sample.begin(), sample.end());
  const std::vector<uint8_t> train = Gather(points, dim, all_rows);
  std::iota(all_rows.begin(), all_rows.end(), 0u);

  VocabularyTree tree;
  tree.dim_ = dim;
  tree.nodes_.emplace_back();
  struct Pending {
    uint32_t node;
    std::vector<uint32_t> rows;  // into train
    uint32_t leaves;
    int levels;
  };
  std::deque<Pending> pending;
  pending.push_back({0, std::move(all_rows), leaves, options.tree_depth});
  double objective = 0;
  while (!pending.empty()) {
    Pending at = std::move(pending.front());
    pending.pop_front();
    if (at.leaves == 1 || at.levels == 0) {
      // A leaf: the squared distances of its points to its centre.
      if (at.node != 0) {
        const float* centre = &tree.centres_[(at.node - 1) * dim];
        for (uint32_t row : at.rows) {
          double d = 0;
          for (std::size_t j = 0; j < dim; ++j) {
            const double diff = train[row * dim + j] - centre[j];
            d += diff * diff;
          }
          objective += d;
        }
      }
      continue;
    }
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
    node.max_points_per_centroid =
        at.levels == 1 ? static_cast<int>((at.rows.size() + k - 1) / k) : kNodePointsPerCentroid;
    node.max_points_per_centroid = std::max(node.max_points_per_centroid, 1);
    MESHSEEK_ASSIGN_OR_RETURN(
        std::vector<float> centres,
        internal::TrainKMeansQuietly(node_points.data(), at.rows.size(), dim, node, nullptr));
    // Every point of the node to its nearest child, as Search() will.
    std::vector<uint32_t> labels(at.rows.size());
    NearestCentroidIndex(centres.data(), k, dim)
        .Search(node_points.data(), at.rows.size(), options.num_threads, labels.data(), nullptr);
    std::vector<std::vector<uint32_t>> child_rows(k);
    for (std::size_t i = 0; i < labels.size(); ++i) child_rows[labels[i]].push_back(at.rows[i]);
    std::vector<std::size_t> counts(k);
    for (uint32_t c = 0; c < k; ++c) counts[c] = child_rows[c].size();
    const std::vector<uint32_t> share = ShareLeaves(at.leaves, counts);

    const auto first = static_cast<uint32_t>(tree.nodes_.size());
    tree.nodes_[at.node].first_child = first;
    tree.nodes_[at.node].num_children = k;
    tree.nodes_.resize(first + k);
    tree.centres_.insert(tree.centres_.end(), centres.begin(), centres.end());
    for (uint32_t c = 0; c < k; ++c) {
      pending.push_back({first + c, std::move(child_rows[c]), share[c], at.levels - 1});
    }
  }
  uint32_t leaf = 0;
  for (Node& node : tree.nodes_) {
    if (node.num_children == 0) node.leaf = leaf++;
  }
  tree.Index();
  if (report != nullptr) {
    *report = KMeansReport();
    report->input_points = n;
    report->training_points = train.size() / dim;
    report->iterations = options.max_iterations;
    report->objective.push_back(objective / static_cast<double>(report->training_points));
  }
  MESHSEEK_LOG(INFO) << "vocabulary tree: " << tree.num_leaves() << " leaves, depth "
                     << tree.depth() << ", " << tree.nodes_.size() << " nodes, from "
                     << train.size() / dim << " of " << n << " points, mean squared distance "
                     << objective / static_cast<double>(train.size() / dim) << ", "
                     << absl::FormatDuration(
                            absl::Trunc(absl::Now() - start, absl::Milliseconds(1)));
  return tree;
}

absl::StatusOr<VocabularyTree> VocabularyTree::FromNodes(std::vector<Node> nodes,
                                                         std::vector<float> centres,
                                                         std::size_t dim) {
  auto bad = [](auto&&... parts) {
    return absl::InvalidArgumentError(absl::StrCat("vocabulary tree: ", parts...));
  };
  if (dim == 0) return bad("dim must be >= 1");
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
  // Each point's node, moved one level down per pass; points bucketed by node
  // (counting sort, stable) so each node searches its points in one block.
  std::vector<uint32_t> at(n, 0);
  std::vector<float> distance(n, 0.0f);
  std::vector<uint32_t> order(n), block_labels;
  std::vector<float> block_distances;
  std::vector<uint8_t> block;
  for (int pass = 0; pass < depth_; ++pass) {
    std::vector<uint32_t> start(nodes_.size() + 1, 0);
    for (std::size_t i = 0; i < n; ++i) ++start[at[i] + 1];
    std::partial_sum(start.begin(), start.end(), start.begin());
    std::vector<uint32_t> fill(start.begin(), start.end() - 1);
    for (std::size_t i = 0; i < n; ++i) order[fill[at[i]]++] = static_cast<uint32_t>(i);
    for (std::size_t node = 0; node < nodes_.size(); ++node) {
      const uint32_t begin = start[node], end = start[node + 1];
      if (begin == end || nodes_[node].num_children == 0) continue;
      const std::size_t m = end - begin;
      block.resize(m * dim_);
      for (std::size_t i = 0; i < m; ++i) {
        std::copy_n(points + static_cast<std::size_t>(order[begin + i]) * dim_, dim_,
                    block.data() + i * dim_);
      }
      block_labels.resize(m);
      block_distances.resize(m);
      children_[node].Search(block.data(), m, num_threads, block_labels.data(),
                             block_distances.data());
      for (std::size_t i = 0; i < m; ++i) {
        at[order[begin + i]] = nodes_[node].first_child + block_labels[i];
        distance[order[begin + i]] = block_distances[i];
      }
    }
  }
  for (std::size_t i = 0; i < n; ++i) {
    labels[i] = nodes_[at[i]].leaf;
    if (squared_distances != nullptr) squared_distances[i] = distance[i];
  }
}

}  // namespace meshseek
