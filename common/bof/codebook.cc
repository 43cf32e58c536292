#include "common/bof/codebook.h"

#include <cmath>
#include <cstring>
#include <limits>
#include <utility>

#include "absl/strings/str_cat.h"
#include "common/base/byte_order.h"
#include "common/base/hash.h"
#include "common/base/status_macros.h"

namespace meshseek {
namespace {

constexpr char kMagic[4] = {'M', 'S', 'C', 'B'};
// Version 1: exact search; version 2: approximate, with its two parameters;
// version 3: a vocabulary tree.
constexpr uint32_t kExactVersion = 1;
constexpr uint32_t kApproximateVersion = 2;
constexpr uint32_t kTreeVersion = 3;
constexpr std::size_t kHeaderBytes = 4 + 4 + 8 + 8;
constexpr std::size_t kApproximateHeaderBytes = kHeaderBytes + 4 + 4;
constexpr std::size_t kChecksumBytes = 8;

absl::Status CheckCentroids(const std::vector<float>& centroids, std::size_t dim) {
  for (std::size_t i = 0; i < centroids.size(); ++i) {
    if (!std::isfinite(centroids[i])) {
      return absl::InvalidArgumentError(absl::StrCat(
          "codebook: centroid ", i / dim, ", coordinate ", i % dim, " is ", centroids[i]));
    }
  }
  return absl::OkStatus();
}

}  // namespace

Codebook::Codebook(std::vector<float> centroids,
                   std::size_t size,
                   std::size_t dim,
                   const std::optional<ApproximateSearchParams>& approximate,
                   int num_threads)
    : centroids_(std::move(centroids)), size_(size), dim_(dim) {
  if (approximate.has_value()) {
    approximate_ = std::make_shared<const ApproximateNearestCentroidIndex>(
        centroids_.data(), size, dim, *approximate, num_threads);
  } else {
    index_ = NearestCentroidIndex(centroids_.data(), size, dim);
  }
}

Codebook::Codebook(VocabularyTree tree)
    : centroids_(tree.LeafCentres()),
      size_(tree.num_leaves()),
      dim_(tree.dim()),
      tree_(std::make_shared<const VocabularyTree>(std::move(tree))) {}

std::optional<ApproximateSearchParams> Codebook::approximate() const {
  if (approximate_ == nullptr) return std::nullopt;
  return approximate_->params();
}

absl::StatusOr<Codebook> Codebook::Train(const uint8_t* descriptors,
                                         std::size_t count,
                                         std::size_t dim,
                                         const KMeansOptions& options,
                                         KMeansReport* report) {
  if (options.assignment == KMeansOptions::Assignment::kTree) {
    MESHSEEK_ASSIGN_OR_RETURN(VocabularyTree tree,
                              VocabularyTree::Train(descriptors, count, dim, options, report));
    return Codebook(std::move(tree));
  }
  MESHSEEK_ASSIGN_OR_RETURN(std::vector<float> centroids,
                            TrainKMeans(descriptors, count, dim, options, report));
  std::optional<ApproximateSearchParams> approximate;
  if (options.UsesApproximateAssignment()) approximate = options.ResolvedApproximateParams();
  return Codebook(std::move(centroids),
                  static_cast<std::size_t>(options.num_centroids),
                  dim,
                  approximate,
                  options.num_threads);
}

absl::StatusOr<Codebook> Codebook::FromCentroids(
    std::vector<float> centroids,
    std::size_t dim,
    std::optional<ApproximateSearchParams> approximate) {
  if (dim == 0) return absl::InvalidArgumentError("codebook: dim must be >= 1, got 0");
  if (centroids.empty() || centroids.size() % dim != 0) {
    return absl::InvalidArgumentError(absl::StrCat("codebook: got ",
                                                   centroids.size(),
                                                   " centroid values, not a positive multiple "
                                                   "of dim ",
                                                   dim));
  }
  const std::size_t size = centroids.size() / dim;
  if (size > std::numeric_limits<uint32_t>::max()) {
    return absl::InvalidArgumentError(
        absl::StrCat("codebook: ", size, " words (at most 2^32 - 1)"));
  }
  if (approximate.has_value() &&
      !(approximate->groups >= 1 && static_cast<std::size_t>(approximate->groups) <= size &&
        approximate->probes >= 1 && approximate->probes <= approximate->groups)) {
    return absl::InvalidArgumentError(absl::StrCat("codebook: approximate search with ",
                                                   approximate->groups,
                                                   " groups and ",
                                                   approximate->probes,
                                                   " probes for ",
                                                   size,
                                                   " words (need 1 <= probes <= groups <= "
                                                   "words)"));
  }
  MESHSEEK_RETURN_IF_ERROR(CheckCentroids(centroids, dim));
  // One thread: a codebook is built on a request path (the service's cache)
  // and the grouping takes well under a second at V = 20,000.
  return Codebook(std::move(centroids), size, dim, approximate, /*num_threads=*/1);
}

absl::StatusOr<std::vector<uint32_t>> Codebook::NearestCentroids(const uint8_t* descriptors,
                                                                 std::size_t count,
                                                                 int num_threads) const {
  if (descriptors == nullptr && count > 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("codebook: descriptors is null with count ", count));
  }
  std::vector<uint32_t> labels(count);
  const int threads = std::max(num_threads, 1);
  if (tree_ != nullptr) {
    tree_->Search(descriptors, count, threads, labels.data(), nullptr);
  } else if (approximate_ != nullptr) {
    approximate_->Search(descriptors, count, threads, labels.data(), nullptr);
  } else {
    index_.Search(descriptors, count, threads, labels.data(), nullptr);
  }
  return labels;
}

absl::StatusOr<std::vector<float>> Codebook::Encode(const uint8_t* descriptors,
                                                    std::size_t count,
                                                    std::size_t dimension,
                                                    int num_threads) const {
  if (count == 0) {
    return absl::InvalidArgumentError(
        "codebook: cannot encode an empty descriptor set (0 descriptors)");
  }
  if (dimension != dim_) {
    return absl::InvalidArgumentError(absl::StrCat(
        "codebook: descriptors of dimension ", dimension, ", the codebook's words have ", dim_));
  }
  MESHSEEK_ASSIGN_OR_RETURN(const std::vector<uint32_t> labels,
                            NearestCentroids(descriptors, count, num_threads));
  std::vector<std::size_t> counts(size(), 0);
  for (uint32_t label : labels) ++counts[label];
  std::vector<float> histogram(size());
  for (std::size_t w = 0; w < size(); ++w) {
    histogram[w] = static_cast<float>(static_cast<double>(counts[w]) / static_cast<double>(count));
  }
  return histogram;
}

std::string Codebook::Serialize() const {
  std::string out(kMagic, sizeof(kMagic));
  if (tree_ != nullptr) {
    PutLittleEndian(kTreeVersion, 4, &out);
    PutLittleEndian(size(), 8, &out);
    PutLittleEndian(dim(), 8, &out);
    PutLittleEndian(tree_->nodes().size(), 4, &out);
    PutLittleEndian(tree_->probes(), 4, &out);
    for (const VocabularyTree::Node& node : tree_->nodes()) {
      PutLittleEndian(node.first_child, 4, &out);
      PutLittleEndian(node.num_children, 4, &out);
      PutLittleEndian(node.leaf, 4, &out);
    }
    for (float v : tree_->centres()) PutFloat(v, &out);
    PutLittleEndian(Fnv1a64(out), 8, &out);
    return out;
  }
  out.reserve(kApproximateHeaderBytes + centroids_.size() * 4 + kChecksumBytes);
  PutLittleEndian(approximate_ != nullptr ? kApproximateVersion : kExactVersion, 4, &out);
  PutLittleEndian(size(), 8, &out);
  PutLittleEndian(dim(), 8, &out);
  if (approximate_ != nullptr) {
    PutLittleEndian(static_cast<uint32_t>(approximate_->params().groups), 4, &out);
    PutLittleEndian(static_cast<uint32_t>(approximate_->params().probes), 4, &out);
  }
  for (float v : centroids_) PutFloat(v, &out);
  PutLittleEndian(Fnv1a64(out), 8, &out);
  return out;
}

absl::StatusOr<Codebook> Codebook::Deserialize(absl::string_view bytes) {
  if (bytes.size() < kHeaderBytes + kChecksumBytes) {
    return absl::InvalidArgumentError(absl::StrCat("codebook: got ",
                                                   bytes.size(),
                                                   " bytes, shorter than the ",
                                                   kHeaderBytes + kChecksumBytes,
                                                   "-byte header and checksum"));
  }
  if (std::memcmp(bytes.data(), kMagic, sizeof(kMagic)) != 0) {
    return absl::InvalidArgumentError("codebook: bad magic (expected \"MSCB\")");
  }
  const uint64_t version = GetLittleEndian(bytes.data() + 4, 4);
  if (version == kTreeVersion) return DeserializeTree(bytes);
  if (version != kExactVersion && version != kApproximateVersion) {
    return absl::InvalidArgumentError(absl::StrCat("codebook: unsupported version ",
                                                   version,
                                                   " (this build reads ",
                                                   kExactVersion,
                                                   " to ",
                                                   kTreeVersion,
                                                   ")"));
  }
  const std::size_t header =
      version == kApproximateVersion ? kApproximateHeaderBytes : kHeaderBytes;
  if (bytes.size() < header + kChecksumBytes) {
    return absl::InvalidArgumentError(absl::StrCat("codebook: got ",
                                                   bytes.size(),
                                                   " bytes, shorter than the version-",
                                                   version,
                                                   " header and checksum (",
                                                   header + kChecksumBytes,
                                                   " bytes)"));
  }
  const uint64_t size = GetLittleEndian(bytes.data() + 8, 8);
  const uint64_t dim = GetLittleEndian(bytes.data() + 16, 8);
  // Both factors are bounded before multiplying, so the byte count cannot overflow.
  const uint64_t max_values = (bytes.size() - header - kChecksumBytes) / 4;
  if (size == 0 || dim == 0 || size > max_values || dim > max_values / size ||
      header + size * dim * 4 + kChecksumBytes != bytes.size()) {
    return absl::InvalidArgumentError(absl::StrCat("codebook: header says ",
                                                   size,
                                                   " words x ",
                                                   dim,
                                                   " dims, inconsistent with ",
                                                   bytes.size(),
                                                   " bytes"));
  }
  const std::size_t payload = bytes.size() - kChecksumBytes;
  if (Fnv1a64(bytes.substr(0, payload)) != GetLittleEndian(bytes.data() + payload, 8)) {
    return absl::InvalidArgumentError("codebook: checksum mismatch (corrupt data)");
  }
  std::optional<ApproximateSearchParams> approximate;
  if (version == kApproximateVersion) {
    // Range-checked by FromCentroids; read through int64 so that values past
    // INT_MAX stay out of range instead of wrapping.
    const int64_t groups = static_cast<int64_t>(GetLittleEndian(bytes.data() + kHeaderBytes, 4));
    const int64_t probes =
        static_cast<int64_t>(GetLittleEndian(bytes.data() + kHeaderBytes + 4, 4));
    if (groups > static_cast<int64_t>(size) || probes > groups) {
      return absl::InvalidArgumentError(absl::StrCat("codebook: approximate search with ",
                                                     groups,
                                                     " groups and ",
                                                     probes,
                                                     " probes for ",
                                                     size,
                                                     " words (need 1 <= probes <= groups <= "
                                                     "words)"));
    }
    approximate = ApproximateSearchParams{static_cast<int>(groups), static_cast<int>(probes)};
  }
  std::vector<float> centroids(size * dim);
  for (std::size_t i = 0; i < centroids.size(); ++i) {
    centroids[i] = GetFloat(bytes.data() + header + 4 * i);
  }
  return FromCentroids(std::move(centroids), dim, approximate);
}

// Version 3. The caller has checked the length against the version-1 header,
// the magic and the version.
absl::StatusOr<Codebook> Codebook::DeserializeTree(absl::string_view bytes) {
  constexpr std::size_t kNodesAt = kHeaderBytes + 8;
  constexpr std::size_t kNodeBytes = 12;
  if (bytes.size() < kNodesAt + kChecksumBytes) {
    return absl::InvalidArgumentError(
        absl::StrCat("codebook: got ", bytes.size(), " bytes, shorter than a tree's header"));
  }
  const uint64_t size = GetLittleEndian(bytes.data() + 8, 8);
  const uint64_t dim = GetLittleEndian(bytes.data() + 16, 8);
  const uint64_t nodes = GetLittleEndian(bytes.data() + kHeaderBytes, 4);
  const auto probes = static_cast<uint32_t>(GetLittleEndian(bytes.data() + kHeaderBytes + 4, 4));
  // Each factor is bounded by the byte count before multiplying.
  const uint64_t room = bytes.size() - kNodesAt - kChecksumBytes;
  if (nodes < 2 || dim == 0 || size == 0 || nodes > room / kNodeBytes ||
      dim > room / 4 / (nodes - 1) ||
      kNodesAt + nodes * kNodeBytes + (nodes - 1) * dim * 4 + kChecksumBytes != bytes.size()) {
    return absl::InvalidArgumentError(absl::StrCat("codebook: header says a tree of ", nodes,
                                                   " nodes x ", dim, " dims, inconsistent with ",
                                                   bytes.size(), " bytes"));
  }
  const std::size_t payload = bytes.size() - kChecksumBytes;
  if (Fnv1a64(bytes.substr(0, payload)) != GetLittleEndian(bytes.data() + payload, 8)) {
    return absl::InvalidArgumentError("codebook: checksum mismatch (corrupt data)");
  }
  std::vector<VocabularyTree::Node> tree_nodes(nodes);
  const char* at = bytes.data() + kNodesAt;
  for (VocabularyTree::Node& node : tree_nodes) {
    node.first_child = static_cast<uint32_t>(GetLittleEndian(at, 4));
    node.num_children = static_cast<uint32_t>(GetLittleEndian(at + 4, 4));
    node.leaf = static_cast<uint32_t>(GetLittleEndian(at + 8, 4));
    at += kNodeBytes;
  }
  std::vector<float> centres((nodes - 1) * dim);
  for (std::size_t i = 0; i < centres.size(); ++i) centres[i] = GetFloat(at + 4 * i);
  MESHSEEK_ASSIGN_OR_RETURN(
      VocabularyTree tree,
      VocabularyTree::FromNodes(std::move(tree_nodes), std::move(centres), dim, probes));
  if (tree.num_leaves() != size) {
    return absl::InvalidArgumentError(absl::StrCat("codebook: header says ", size,
                                                   " words, the tree has ", tree.num_leaves()));
  }
  return Codebook(std::move(tree));
}

}  // namespace meshseek
