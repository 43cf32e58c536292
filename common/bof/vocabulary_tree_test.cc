#include "common/bof/vocabulary_tree.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <set>
#include <vector>

#include "common/bof/codebook.h"
#include "common/bof/nearest_centroid.h"

namespace meshseek {
namespace {

constexpr std::size_t kDim = 16;

// uint8 points around 60 random centres, as quantised descriptors cluster.
std::vector<uint8_t> Points(std::size_t n, uint32_t seed) {
  std::mt19937 rng(seed);
  std::vector<uint8_t> centres(60 * kDim);
  for (uint8_t& v : centres) v = static_cast<uint8_t>(rng() % 200 + 20);
  std::normal_distribution<float> noise(0.0f, 8.0f);
  std::vector<uint8_t> points(n * kDim);
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t c = rng() % 60;
    for (std::size_t d = 0; d < kDim; ++d) {
      const float v = centres[c * kDim + d] + noise(rng);
      points[i * kDim + d] = static_cast<uint8_t>(std::clamp(v, 0.0f, 255.0f));
    }
  }
  return points;
}

KMeansOptions TreeOptions(int leaves, int depth) {
  KMeansOptions options;
  options.num_centroids = leaves;
  options.assignment = KMeansOptions::Assignment::kTree;
  options.tree_depth = depth;
  options.max_iterations = 8;
  options.seed = 7;
  options.num_threads = 1;
  return options;
}

TEST(VocabularyTreeTest, HasExactlyTheLeavesAskedAndTheDepth) {
  const std::vector<uint8_t> points = Points(20000, 1);
  for (int depth : {1, 2, 3}) {
    auto tree = VocabularyTree::Train(points.data(), 20000, kDim, TreeOptions(500, depth));
    ASSERT_TRUE(tree.ok()) << tree.status();
    EXPECT_EQ(tree->num_leaves(), 500u);
    EXPECT_EQ(tree->depth(), depth);
    std::set<uint32_t> words;
    for (const VocabularyTree::Node& node : tree->nodes()) {
      if (node.num_children == 0) words.insert(node.leaf);
    }
    EXPECT_EQ(words.size(), 500u);
    EXPECT_EQ(*words.rbegin(), 499u);
  }
}

TEST(VocabularyTreeTest, SearchIsTheDescentAndTrainingPointsUseEveryLeaf) {
  const std::vector<uint8_t> points = Points(20000, 2);
  auto tree = VocabularyTree::Train(points.data(), 20000, kDim, TreeOptions(400, 2));
  ASSERT_TRUE(tree.ok()) << tree.status();
  std::vector<uint32_t> labels(20000);
  std::vector<float> distances(20000);
  tree->Search(points.data(), 20000, 1, labels.data(), distances.data());
  // The descent by hand for a few points: nearest child at every node.
  for (std::size_t i = 0; i < 50; ++i) {
    uint32_t node = 0;
    while (tree->nodes()[node].num_children > 0) {
      const VocabularyTree::Node& n = tree->nodes()[node];
      uint32_t child = 0;
      NearestCentroidIndex(&tree->centres()[(n.first_child - 1) * kDim], n.num_children, kDim)
          .Search(&points[i * kDim], 1, 1, &child, nullptr);
      node = n.first_child + child;
    }
    EXPECT_EQ(labels[i], tree->nodes()[node].leaf) << "point " << i;
    const std::vector<float> leaves = tree->LeafCentres();
    double d = 0;
    for (std::size_t j = 0; j < kDim; ++j) {
      const double diff = points[i * kDim + j] - leaves[labels[i] * kDim + j];
      d += diff * diff;
    }
    EXPECT_NEAR(distances[i], d, 1e-2 * d + 1e-3);
  }
  // Leaves are shared by points, so the training points reach all of them.
  EXPECT_EQ(std::set<uint32_t>(labels.begin(), labels.end()).size(), 400u);
}

TEST(VocabularyTreeTest, MoreProbesFindTheNearestLeafMoreOften) {
  const std::vector<uint8_t> points = Points(20000, 9);
  KMeansOptions options = TreeOptions(400, 3);
  std::vector<double> agreement;
  for (int probes : {1, 2, 8}) {
    options.tree_probes = probes;
    auto tree = VocabularyTree::Train(points.data(), 20000, kDim, options);
    ASSERT_TRUE(tree.ok()) << tree.status();
    EXPECT_EQ(tree->probes(), static_cast<uint32_t>(probes));
    const std::vector<float> leaves = tree->LeafCentres();
    std::vector<uint32_t> exact(5000), found(5000);
    std::vector<float> exact_d(5000), found_d(5000);
    NearestCentroidIndex(leaves.data(), 400, kDim)
        .Search(points.data(), 5000, 1, exact.data(), exact_d.data());
    tree->Search(points.data(), 5000, 1, found.data(), found_d.data());
    std::size_t same = 0;
    for (std::size_t i = 0; i < 5000; ++i) {
      same += exact[i] == found[i];
      EXPECT_GE(found_d[i], exact_d[i] * (1 - 1e-5f) - 1e-3f);
    }
    agreement.push_back(same / 5000.0);
  }
  // The same tree each time (probes do not change training), searched wider.
  EXPECT_LT(agreement[0], agreement[1]);
  EXPECT_LE(agreement[1], agreement[2]);
  EXPECT_GT(agreement[2], 0.97);
}

TEST(VocabularyTreeTest, BitIdenticalForAnyThreadCountAndSeeded) {
  const std::vector<uint8_t> points = Points(15000, 3);
  KMeansOptions one = TreeOptions(300, 2);
  KMeansOptions two = one;
  two.num_threads = 2;
  auto a = VocabularyTree::Train(points.data(), 15000, kDim, one);
  auto b = VocabularyTree::Train(points.data(), 15000, kDim, two);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_EQ(a->centres(), b->centres());
  std::vector<uint32_t> la(15000), lb(15000);
  a->Search(points.data(), 15000, 1, la.data(), nullptr);
  b->Search(points.data(), 15000, 2, lb.data(), nullptr);
  EXPECT_EQ(la, lb);
  KMeansOptions other = one;
  other.seed = 8;
  auto c = VocabularyTree::Train(points.data(), 15000, kDim, other);
  ASSERT_TRUE(c.ok());
  EXPECT_NE(a->centres(), c->centres());
}

TEST(VocabularyTreeTest, CodebookRoundTripsTheTreeAndEncodesAsItDid) {
  const std::vector<uint8_t> points = Points(12000, 4);
  KMeansOptions options = TreeOptions(250, 3);
  options.tree_probes = 3;
  auto codebook = Codebook::Train(points.data(), 12000, kDim, options);
  ASSERT_TRUE(codebook.ok()) << codebook.status();
  ASSERT_NE(codebook->tree(), nullptr);
  EXPECT_EQ(codebook->size(), 250u);
  auto back = Codebook::Deserialize(codebook->Serialize());
  ASSERT_TRUE(back.ok()) << back.status();
  ASSERT_NE(back->tree(), nullptr);
  EXPECT_EQ(back->tree()->probes(), 3u);
  EXPECT_EQ(back->centroids(), codebook->centroids());
  EXPECT_EQ(back->Serialize(), codebook->Serialize());
  EXPECT_EQ(*back->NearestCentroids(points.data(), 12000),
            *codebook->NearestCentroids(points.data(), 12000));
}

TEST(VocabularyTreeTest, DeserializeRejectsAnInconsistentTree) {
  const std::vector<uint8_t> points = Points(6000, 5);
  auto codebook = Codebook::Train(points.data(), 6000, kDim, TreeOptions(100, 2));
  ASSERT_TRUE(codebook.ok()) << codebook.status();
  const std::string bytes = codebook->Serialize();
  // Truncated, and every header field but the version changed.
  EXPECT_FALSE(Codebook::Deserialize(bytes.substr(0, bytes.size() - 5)).ok());
  for (std::size_t at : {8, 16, 24}) {
    std::string bad = bytes;
    bad[at] = static_cast<char>(bad[at] + 1);
    EXPECT_FALSE(Codebook::Deserialize(bad).ok()) << "byte " << at;
  }
  // A structure that does not hold together, checksum right.
  std::vector<VocabularyTree::Node> nodes = codebook->tree()->nodes();
  std::vector<float> centres = codebook->tree()->centres();
  auto broken = nodes;
  broken[0].first_child = 2;
  EXPECT_FALSE(VocabularyTree::FromNodes(broken, centres, kDim, 1).ok());
  broken = nodes;
  for (auto& node : broken) {
    if (node.num_children == 0) node.leaf = 0;
  }
  EXPECT_FALSE(VocabularyTree::FromNodes(broken, centres, kDim, 1).ok());
  centres.pop_back();
  EXPECT_FALSE(VocabularyTree::FromNodes(nodes, centres, kDim, 1).ok());
}

TEST(VocabularyTreeTest, TheSampleAloneGivesTheWholeSetsTree) {
  const std::vector<uint8_t> points = Points(30000, 10);
  KMeansOptions options = TreeOptions(200, 2);
  options.max_points_per_centroid = 50;  // a sample of 10,000 of the 30,000
  auto whole = VocabularyTree::Train(points.data(), 30000, kDim, options);
  ASSERT_TRUE(whole.ok()) << whole.status();
  std::vector<uint8_t> sample;
  for (std::size_t row : KMeansTrainingRows(30000, options)) {
    sample.insert(sample.end(), &points[row * kDim], &points[(row + 1) * kDim]);
  }
  KMeansOptions sent = options;
  sent.sampled_from = 30000;
  auto part = VocabularyTree::Train(sample.data(), sample.size() / kDim, kDim, sent);
  ASSERT_TRUE(part.ok()) << part.status();
  EXPECT_EQ(part->centres(), whole->centres());
  // A sample of another size is refused.
  EXPECT_FALSE(VocabularyTree::Train(sample.data(), sample.size() / kDim - 1, kDim, sent).ok());
}

TEST(VocabularyTreeTest, OptionsAreValidated) {
  const std::vector<uint8_t> points = Points(1000, 6);
  KMeansOptions options = TreeOptions(100, 0);
  EXPECT_FALSE(VocabularyTree::Train(points.data(), 1000, kDim, options).ok());
  options.tree_depth = 9;
  EXPECT_FALSE(VocabularyTree::Train(points.data(), 1000, kDim, options).ok());
  EXPECT_FALSE(VocabularyTree::Train(points.data(), 50, kDim, TreeOptions(100, 2)).ok());
  // Flat k-means refuses to train a tree.
  std::vector<float> floats(points.begin(), points.end());
  EXPECT_FALSE(TrainKMeans(floats.data(), 1000, kDim, TreeOptions(100, 2)).ok());
}

}  // namespace
}  // namespace meshseek
