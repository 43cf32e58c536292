// A vocabulary tree (Nistér & Stewénius, "Scalable recognition with a
// vocabulary tree", CVPR 2006): the visual words are the leaves of a tree
// learnt by hierarchical k-means, and a descriptor's word is found by walking
// down from the root, at each node to the nearest of its children.
//
// Why. A flat vocabulary of V words costs V distances a descriptor to encode
// exactly, and the two-level search (approximate_nearest_centroid.h) about
// 2 sqrt(probes V): 1,130 at BF-DSIFT's V = 40,000 with 8 probes, which made
// encoding one McGill model's 25,000 descriptors 190 ms of a query and
// training 26 s of 2 cores (bench/results/codebook.txt). A tree of depth L
// with about V^(1/L) children a node costs L V^(1/L) distances: 105 at
// V = 40,000, L = 3. Training is one k-means per node over the node's own
// points, and only the top levels see many points.
//
// Method (Train). The training points are KMeansTrainingRows' sample, as for a
// flat vocabulary. A node that is to hold t leaves at d levels above the
// leaves is split by exact k-means into k = round(t^(1/d)) children (k = t
// at the last level), and its t leaves are shared among the children in
// proportion to the points each child received (one at a time to the child
// furthest below its share; at least one each, at most a child's points), so
// that leaves hold about as many
// points as a flat vocabulary's words and the tree has exactly V leaves. A
// child with one leaf is a leaf. Internal nodes' k-means runs on at most
// kNodePointsPerCentroid points a child (its centres need few); a last-level
// node's on all of its points; every point then goes down to its nearest
// child. Last, kRefinements Lloyd steps over the leaves: every training point
// to its leaf by Search() (with the tree's probes), each leaf's centre to the
// mean of its points; the inner nodes stay as grown.
//
// Determinism. Nodes are numbered breadth first; node i's k-means is seeded
// with a function of the options' seed and i, and every k-means and search is
// bit-identical for any thread count (kmeans.h, nearest_centroid.h), so the
// tree is too. Leaves are numbered in node order.
//
// Search. The plain descent misses the nearest leaf when a point lies near a
// boundary of an upper level; keeping the `probes` nearest nodes at each level
// (a beam) finds most of those, at about probes x depth x V^(1/depth)
// distances.
//
// Layout. Nodes in one array, breadth first: a node's children are
// consecutive. Each internal node holds an exact index over its children's
// centres; Search() moves all points down one level at a time, bucketing them
// by node, so each node's index searches its points as one block.
#ifndef MESHSEEK_COMMON_BOF_VOCABULARY_TREE_H_
#define MESHSEEK_COMMON_BOF_VOCABULARY_TREE_H_

#include <cstddef>
#include <cstdint>
#include <vector>

#include "absl/status/statusor.h"
#include "common/bof/kmeans.h"
#include "common/bof/nearest_centroid.h"

namespace meshseek {

// Immutable once built; Search() may be called from several threads at once.
class VocabularyTree {
 public:
  /// Sub-sample bound of an internal node's k-means, in points a child.
  static constexpr int kNodePointsPerCentroid = 256;
  /// Lloyd steps over the leaves after growing (see Method).
  static constexpr int kRefinements = 2;
  /// Most nodes a search keeps a level (KMeansOptions::tree_probes).
  static constexpr uint32_t kMaxProbes = 64;

  /// One node: an internal node's children are nodes [first_child,
  /// first_child + num_children); a leaf has none and its word index.
  struct Node {
    uint32_t first_child = 0;
    uint32_t num_children = 0;
    uint32_t leaf = 0;
  };

  /// Learns a tree of options.num_centroids leaves and options.tree_depth
  /// levels over `n` row-major uint8 points of `dim` values (options as for
  /// TrainKMeans: the sample, iterations, seed and threads; the assignment of
  /// every node is exact). Errors are TrainKMeans's.
  static absl::StatusOr<VocabularyTree> Train(const uint8_t* points,
                                              std::size_t n,
                                              std::size_t dim,
                                              const KMeansOptions& options,
                                              KMeansReport* report = nullptr);

  /// A tree from its parts (as Serialize wrote them): `nodes` breadth first,
  /// node 0 the root, and `centres` (nodes.size() - 1) x dim, node i's at row
  /// i - 1. InvalidArgument naming the first inconsistency (a child range
  /// outside the array or not after its parent, a leaf index repeated or out of
  /// 0..V-1, a node that is neither, sizes, non-finite values).
  static absl::StatusOr<VocabularyTree> FromNodes(std::vector<Node> nodes,
                                                  std::vector<float> centres,
                                                  std::size_t dim,
                                                  uint32_t probes);

  /// Number of leaves V.
  std::size_t num_leaves() const { return leaf_node_.size(); }
  std::size_t dim() const { return dim_; }
  /// Levels below the root on the longest path.
  int depth() const { return depth_; }
  /// Nodes the search keeps at each level (1: the plain descent).
  uint32_t probes() const { return probes_; }
  const std::vector<Node>& nodes() const { return nodes_; }
  /// (nodes().size() - 1) x dim: node i's centre at row i - 1.
  const std::vector<float>& centres() const { return centres_; }
  /// V x dim: the leaves' centres in leaf order (the words).
  std::vector<float> LeafCentres() const;

  /// For each of the `n` row-major points, its leaf (labels[i]) and, when
  /// `squared_distances` is not null, the squared distance to that leaf's
  /// centre: the nearest leaf under the probes() nearest nodes kept at each
  /// level (a beam search; ties to the lower node). With one probe it is the
  /// descent that partitioned the training points. Runs on up to
  /// `num_threads` threads (<= 0: all cores); the result does not depend on it.
  void Search(const uint8_t* points,
              std::size_t n,
              int num_threads,
              uint32_t* labels,
              float* squared_distances) const;

 private:
  VocabularyTree() = default;
  // Points are searched in blocks of this many (the unit of parallelism).
  static constexpr std::size_t kPointsPerBlock = 4096;
  // Builds the children's indexes, leaf_node_ and depth_ from nodes_ and
  // centres_ (already checked).
  void Index();
  // Hierarchical k-means over `train` (dim_ bytes a point): nodes_,
  // centres_, the leaves' numbers and the indexes.
  absl::Status Grow(const std::vector<uint8_t>& train, const KMeansOptions& options);
  // `iterations` Lloyd steps over the leaves, each point assigned by
  // Search(); returns the mean squared distance of each assignment
  // (iterations + 1 values: after growing, after each step).
  std::vector<double> Refine(const std::vector<uint8_t>& train, int iterations, int num_threads);
  void SearchBlock(const uint8_t* points,
                   std::size_t count,
                   uint32_t* labels,
                   float* squared_distances) const;

  std::size_t dim_ = 0;
  int depth_ = 0;
  uint32_t probes_ = 1;
  std::vector<Node> nodes_;
  std::vector<float> centres_;
  // Per node: an index over its children's centres (empty for a leaf).
  std::vector<NearestCentroidIndex> children_;
  // Per leaf: its node.
  std::vector<uint32_t> leaf_node_;
};

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_BOF_VOCABULARY_TREE_H_
