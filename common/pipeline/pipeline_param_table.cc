// The parameter table (pipeline_params.h): one row per parameter, in the
// order of --help and metrics.json. Columns: name; the range of a number (or
// the names of an enumerator's values); the methods it applies to; the field
// it lives in, of the selected method's options (OF) or of the collection's
// (OF_COLLECTION); the one-line help. The type is the field's. Defaults are not
// a column: they stay in the option structs, where the core library, the
// benchmarks and the tests read them without the table, so each default is
// written once (FeatureMethodInfo may set a method's own, e.g. its
// vocabulary).
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <initializer_list>
#include <limits>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "common/pipeline/param_value_text.h"
#include "common/pipeline/pipeline_params.h"
#include "common/search/neighbor_graph.h"
#include "common/search/sparse_histogram.h"

namespace meshseek {
namespace {

using Options = RetrievalPipelineOptions;
using Scope = ParamSpec::Scope;
constexpr FeatureMethod kDld = FeatureMethod::kDldSift;
constexpr FeatureMethod kLd = FeatureMethod::kLdSift;
constexpr FeatureMethod kRld = FeatureMethod::kRldSift;
constexpr FeatureMethod kBf = FeatureMethod::kBfDsift;
constexpr FeatureMethod kLfd = FeatureMethod::kLfd;
constexpr FeatureMethod kLsf = FeatureMethod::kLsf;

// Second column: a numeric range (of each element of a list), or the names of
// an enumerator's values.
struct Domain {
  double min = 0;
  double max = 0;
  std::vector<std::pair<std::string, int>> names;
};
Domain Range(double min, double max) { return {min, max, {}}; }
template <typename E>
Domain Names(std::initializer_list<std::pair<const char*, E>> names) {
  Domain domain;
  for (const auto& [text, value] : names) domain.names.emplace_back(text, static_cast<int>(value));
  return domain;
}

// Third column: the methods a parameter applies to.
struct Applies {
  Scope scope;
  std::vector<FeatureMethod> methods;
};
Applies Only(std::initializer_list<FeatureMethod> methods) { return {Scope::kListed, methods}; }
const Applies kSiftMethods = Only({kDld, kLd, kRld, kBf});
const Applies kBagOfFeatures{Scope::kBagOfFeatures, {}};
const Applies kTheCollection{Scope::kCollection, {}};

template <typename T>
constexpr ParamType TypeOf() {
  if constexpr (std::is_enum_v<T>) return ParamType::kChoice;
  if constexpr (std::is_same_v<T, int>) return ParamType::kInt;
  if constexpr (std::is_same_v<T, uint64_t>) return ParamType::kUint64;
  if constexpr (std::is_same_v<T, double>) return ParamType::kDouble;
  if constexpr (std::is_same_v<T, bool>) return ParamType::kBool;
  if constexpr (std::is_same_v<T, std::vector<double>>) return ParamType::kDoubleList;
}

// One row as a ParamSpec. Target is RetrievalPipelineOptions (a method's
// parameter) or CollectionOptions (the collection's).
template <typename T, typename Target>
ParamSpec Param(
    const char* name, Domain domain, const Applies& applies, T& (*field)(Target&), const char* doc) {
  constexpr bool kOfCollection = std::is_same_v<Target, CollectionOptions>;
  if (kOfCollection != (applies.scope == Scope::kCollection)) {
    std::fprintf(stderr, "pipeline parameter table: %s: a field of the collection's options "
                 "must apply to the collection, and only it\n", name);
    std::abort();
  }
  ParamSpec spec;
  spec.name = name;
  spec.type = TypeOf<T>();
  spec.doc = doc;
  spec.min = domain.min;
  spec.max = domain.max;
  spec.scope = applies.scope;
  spec.methods = applies.methods;
  std::function<std::string(const Target&)> get;
  std::function<void(absl::string_view, Target*)> set;
  if constexpr (std::is_enum_v<T>) {
    for (const auto& [text, value] : domain.names) spec.choices.push_back(text);
    get = [field, names = domain.names](const Target& o) {
      const int current = static_cast<int>(field(const_cast<Target&>(o)));
      for (const auto& [text, value] : names) {
        if (value == current) return text;
      }
      return std::string("?");
    };
    set = [field, names = domain.names](absl::string_view text, Target* o) {
      for (const auto& [choice, value] : names) {
        if (choice == text) field(*o) = static_cast<T>(value);
      }
    };
  } else {
    get = [field](const Target& o) { return param_text::Format(field(const_cast<Target&>(o))); };
    set = [field](absl::string_view text, Target* o) { param_text::Parse(text, &field(*o)); };
  }
  if constexpr (kOfCollection) {
    spec.collection_get = std::move(get);
    spec.collection_set = std::move(set);
  } else {
    spec.get = std::move(get);
    spec.set = std::move(set);
  }
  return spec;
}

// "method" selects every other parameter's meaning and default: setting it
// starts from that method's defaults. Its choices are the method table's.
ParamSpec MethodParam() {
  ParamSpec method;
  method.name = "method";
  method.type = ParamType::kChoice;
  method.scope = Scope::kAll;
  std::vector<std::string> titles;
  for (const FeatureMethodInfo& info : FeatureMethods()) {
    method.choices.push_back(info.name);
    titles.push_back(absl::StrCat(info.name, " (", info.title, ")"));
  }
  method.doc = absl::StrCat("feature method, or several joined by + (fused): ",
                            absl::StrJoin(titles, " | "));
  method.get = [](const Options& o) { return std::string(FeatureMethodName(o.extractor.method)); };
  method.set = [](absl::string_view text, Options* o) {
    *o = Options::ForMethod(*ParseFeatureMethod(text));
  };
  return method;
}

// The field a row's parameter lives in.
#define OF(field) +[](Options & o) -> auto& { return field; }

// A parameter that lives in a different field of each method's options: a
// table of (method, field) rows, looked up by the selected method. The
// parameter applies to exactly these methods (its Only() column), so the
// lookup always finds its row; the first row answers otherwise.
template <typename T>
class MethodFields {
 public:
  struct Row {
    FeatureMethod method;
    T& (*field)(Options&);
  };
  MethodFields(std::initializer_list<Row> rows) : rows_(rows) {}
  T& Of(Options& o) const {
    for (const Row& row : rows_) {
      if (row.method == o.extractor.method) return row.field(o);
    }
    return rows_.front().field(o);
  }

 private:
  std::vector<Row> rows_;
};

// The sub-options and fields parameters share between methods.
const MethodFields<DepthImageOptions> kDepthImage = {
    {kDld, OF(o.extractor.dld.depth_image)},
    {kLd, OF(o.extractor.ld.depth_image)},
    {kRld, OF(o.extractor.rld.depth_image)},
    {kBf, OF(o.extractor.bfdsift.patch_image)}};
const MethodFields<SiftDescriptorOptions> kSift = {
    {kDld, OF(o.extractor.dld.descriptor)},
    {kLd, OF(o.extractor.ld.descriptor)},
    {kRld, OF(o.extractor.rld.descriptor)},
    {kBf, OF(o.extractor.bfdsift.descriptor)}};
const MethodFields<ScaleSpaceOptions> kScaleSpace = {
    {kRld, OF(o.extractor.rld.scale_space)},
    {kLd, OF(o.extractor.ld.scale_space)}};
const MethodFields<double> kScale = {
    {kDld, OF(o.extractor.dld.scale)},
    {kLsf, OF(o.extractor.lsf.scale)}};
const MethodFields<int> kPoints = {
    {kDld, OF(o.extractor.dld.num_points)},
    {kLsf, OF(o.extractor.lsf.num_points)}};
const MethodFields<bool> kWeightedFrame = {
    {kDld, OF(o.extractor.dld.weighted_frame)},
    {kRld, OF(o.extractor.rld.weighted_frame)}};
const MethodFields<int> kViewSize = {
    {kBf, OF(o.extractor.bfdsift.view_size)},
    {kLfd, OF(o.extractor.lfd.image_size)}};

#define OF_COLLECTION(field) +[](CollectionOptions & o) -> auto& { return field; }

// The rows of the features: where they are, the views, the depth images.
std::vector<ParamSpec> FeatureRows() {
  // clang-format off
  return {
    MethodParam(),
    // Where the features are, and their support.
    Param("scale", Range(1e-6, 2), Only({kDld, kLsf}),
          OF(kScale.Of(o)),
          "support radius E relative to the minimum enclosing sphere (s = E * D / 2)"),
    Param("points", Range(1, 1000000), Only({kDld, kLsf}),
          OF(kPoints.Of(o)),
          "feature points per model (N_DLD, LSF's centres)"),
    Param("extra_scales", Range(1e-6, 2), Only({kLsf}), OF(o.extractor.lsf.extra_scales),
          "further support radii (as scale), every centre described at each"),
    Param("samples_per_support", Range(8, 100000), Only({kLsf}), OF(o.extractor.lsf.samples_per_support),
          "oriented surface samples in a flat disc of the support radius"),
    Param("distance_bins", Range(1, 64), Only({kLsf}), OF(o.extractor.lsf.distance_bins),
          "histogram bins over the distance to the centre"),
    Param("angle_bins", Range(1, 64), Only({kLsf}), OF(o.extractor.lsf.angle_bins),
          "histogram bins over each normal angle"),
    Param("frame_samples", Range(8, 1000000), Only({kDld}), OF(o.extractor.dld.frame_samples_per_support),
          "dense surface samples per support disc for the local PCA frame"),
    Param("frame_radius", Range(0.25, 4), Only({kDld}), OF(o.extractor.dld.frame_radius_factor),
          "the local frame uses the samples within this many support radii"),
    Param("weighted_frame", Range(0, 1), Only({kDld, kRld}),
          OF(kWeightedFrame.Of(o)),
          "distance-weighted (SHOT-style) PCA frame instead of plain PCA"),
    Param("rld_samples", Range(100, 10000000), Only({kRld}), OF(o.extractor.rld.num_samples),
          "resample points (N_RLD)"),
    Param("rld_neighbors", Range(1, 100), Only({kRld}), OF(o.extractor.rld.neighbors),
          "k of the k-nearest-neighbour graph"),
    Param("levels", Range(2, 200), Only({kLd, kRld}), OF(kScaleSpace.Of(o).levels),
          "scale-space levels L"),
    Param("scale_factor", Range(1e-6, 1e6), Only({kLd, kRld}), OF(kScaleSpace.Of(o).scale_factor),
          "C in the feature scale s = C * d * sqrt(level)"),
    // Whole-model views (BF-DSIFT, LFD).
    Param("view_level", Range(0, 3), Only({kBf}), OF(o.extractor.bfdsift.view_level),
          "view directions: vertices of the icosahedron subdivided this often (1: 42)"),
    Param("view_size", Range(32, 1024), Only({kBf, kLfd}),
          OF(kViewSize.Of(o)),
          "side of each whole-model view in pixels"),
    Param("contour_samples", Range(21, 65536), Only({kLfd}), OF(o.extractor.lfd.contour_samples),
          "points the silhouette's outer contour is resampled to (Fourier)"),
    Param("zernike_radius",
          Names<LfdZernikeRadius>({{"view", LfdZernikeRadius::kPerView},
                                   {"lightfield", LfdZernikeRadius::kPerLightField}}),
          Only({kLfd}), OF(o.extractor.lfd.zernike_radius),
          "Zernike disc radius: per view | per light field (the original's)"),
    Param("points_per_view", Range(1, 100000), Only({kBf}), OF(o.extractor.bfdsift.points_per_view),
          "dense grid points per view inside the silhouette"),
    Param("patch_radius", Range(1e-3, 0.5), Only({kBf}), OF(o.extractor.bfdsift.patch_radius),
          "smallest SIFT patch radius relative to the view's side"),
    Param("patch_scales", Range(1, 4), Only({kBf}), OF(o.extractor.bfdsift.patch_scales),
          "patch radii per point: patch_radius, twice it, ..."),
    // Depth images and their SIFT descriptors.
    Param("image_size", Range(3, 255), kSiftMethods, OF(kDepthImage.Of(o).image_size),
          "local depth image side I in pixels (odd)"),
    Param("orientation",
          Names<ImageOrientation>({{"dominant", ImageOrientation::kDominant},
                                   {"up", ImageOrientation::kUpAxis}}),
          kSiftMethods, OF(kSift.Of(o).orientation),
          "descriptor rotation: Lowe's gradient peaks | PCA up axis + 180-degree sum"),
    Param("depth_to_gray",
          Names<DepthToGray>({{"fixed", DepthToGray::kFixedRange}, {"stretch", DepthToGray::kStretch}}),
          kSiftMethods, OF(kSift.Of(o).depth_to_gray),
          "depth to grey: fixed (2s range) | stretch (image range)"),
    Param("max_orientations", Range(0, 36), kSiftMethods, OF(kSift.Of(o).max_orientations),
          "with dominant orientation: at most this many descriptors per image (0: every peak "
          "within 80 % of the highest)"),
    Param("blur_sigma", Range(0.5, 5), kSiftMethods, OF(kSift.Of(o).blur_sigma),
          "SIFT blur sigma in pixels"),
  };
  // clang-format on
}

// The rows of the codebook, the histograms' ranking and the collection's
// fusion.
std::vector<ParamSpec> RankingRows() {
  using Assignment = KMeansOptions::Assignment;
  using Rerank = RerankOptions::Method;
  const double kMaxSeed = static_cast<double>(std::numeric_limits<uint64_t>::max());
  // clang-format off
  return {
    // The codebook and the histograms' ranking.
    Param("vocabulary", Range(1, kMaxVocabulary), kBagOfFeatures, OF(o.kmeans.num_centroids),
          "codebook size V (k-means centroids)"),
    Param("kmeans_points_per_centroid", Range(1, 1000000), kBagOfFeatures,
          OF(o.kmeans.max_points_per_centroid),
          "k-means trains on at most this many features per centroid"),
    Param("kmeans_iterations", Range(1, 10000), kBagOfFeatures, OF(o.kmeans.max_iterations),
          "maximum k-means iterations"),
    Param("kmeans_assignment",
          Names<Assignment>({{"auto", Assignment::kAuto},
                             {"exact", Assignment::kExact},
                             {"approximate", Assignment::kApproximate},
                             {"tree", Assignment::kTree}}),
          kBagOfFeatures, OF(o.kmeans.assignment),
          "nearest-word search of k-means and encoding: auto (exact below V = 1,000, approximate "
          "from there) | exact | approximate | tree (the words a vocabulary tree's leaves)"),
    Param("kmeans_tree_depth", Range(1, 8), kBagOfFeatures, OF(o.kmeans.tree_depth),
          "levels of the vocabulary tree (kmeans_assignment=tree): about depth x V^(1/depth) "
          "distances a descriptor"),
    Param("kmeans_tree_probes", Range(1, 64), kBagOfFeatures, OF(o.kmeans.tree_probes),
          "nodes the vocabulary tree's search keeps at each level (1: the plain descent)"),
    Param("seed", Range(0, kMaxSeed), kBagOfFeatures, OF(o.kmeans.seed),
          "seed of k-means sampling and seeding"),
    Param("idf", Range(0, 1), kBagOfFeatures, OF(o.weighting.idf),
          "weight histogram words by inverse document frequency over the collection (tf-idf)"),
    Param("histogram_power", Range(0.01, 1), kBagOfFeatures, OF(o.weighting.power),
          "raise histogram bins to this power before ranking (0.5: square root; 1: none)"),
    Param("kl_epsilon", Range(1e-30, 0.5), kBagOfFeatures, OF(o.kl.epsilon),
          "mass added to every histogram bin before KL divergence (zero-bin rule)"),
    // The collection's: how the methods' distances become one ranking.
    Param("weights", Range(0, 1000), kTheCollection, OF_COLLECTION(o.weights),
          "fusion weight of each method, in the order named (several methods)"),
    Param("rerank", Names<Rerank>({{"none", Rerank::kNone}, {"kreciprocal", Rerank::kKReciprocal}}),
          kTheCollection, OF_COLLECTION(o.rerank.method),
          "re-ranking over the collection's neighbour graph: none | kreciprocal (k-reciprocal "
          "encoding)"),
    Param("rerank_k1", Range(1, NeighborGraph::kMaxK - 1), kTheCollection, OF_COLLECTION(o.rerank.k1),
          "re-ranking: neighbourhood whose reciprocal members describe a model"),
    Param("rerank_k2", Range(1, NeighborGraph::kMaxK), kTheCollection, OF_COLLECTION(o.rerank.k2),
          "re-ranking: nearest models averaged in local query expansion (1: none)"),
    Param("rerank_lambda", Range(0, 1), kTheCollection, OF_COLLECTION(o.rerank.lambda),
          "re-ranking: weight of the original distance"),
    Param("rerank_depth", Range(1, 100000), kTheCollection, OF_COLLECTION(o.rerank.depth),
          "re-ranking: models re-ranked per query"),
  };
  // clang-format on
}

std::vector<ParamSpec> MakeTable() {
  std::vector<ParamSpec> table = FeatureRows();
  for (ParamSpec& row : RankingRows()) table.push_back(std::move(row));
  return table;
}

#undef OF
#undef OF_COLLECTION

}  // namespace

bool ParamSpec::AppliesTo(FeatureMethod method) const {
  switch (scope) {
    case Scope::kAll:
      return true;
    case Scope::kBagOfFeatures:
      return FeatureMethodInfoOf(method).kind == DescriptorKind::kBagOfFeatures;
    case Scope::kListed:
      for (FeatureMethod m : methods) {
        if (m == method) return true;
      }
      return false;
    case Scope::kCollection:
      return false;
  }
  return false;
}

std::string ParamSpec::TypeDescription() const {
  switch (type) {
    case ParamType::kInt:
      return absl::StrCat(
          "an integer in [", static_cast<int64_t>(min), ", ", static_cast<int64_t>(max), "]");
    case ParamType::kUint64:
      return "an unsigned 64-bit integer";
    case ParamType::kDouble:
      return absl::StrCat("a number in [", param_text::Format(min), ", ", param_text::Format(max), "]");
    case ParamType::kBool:
      return "true or false";
    case ParamType::kChoice:
      return absl::StrCat("one of ", absl::StrJoin(choices, ", "));
    case ParamType::kDoubleList:
      return absl::StrCat("up to 8 comma-separated numbers in [", param_text::Format(min), ", ", param_text::Format(max), "]");
  }
  return "?";
}

std::string ParamSpec::AppliesToText() const {
  switch (scope) {
    case Scope::kAll:
      return "every method";
    case Scope::kBagOfFeatures:
      return "bag-of-features methods";
    case Scope::kCollection:
      return "the collection";
    case Scope::kListed:
      break;
  }
  std::vector<std::string> names;
  for (FeatureMethod m : methods) names.push_back(FeatureMethodName(m));
  return absl::StrJoin(names, ", ");
}

const std::vector<ParamSpec>& PipelineParamSpecs() {
  static const auto* const kSpecs = new std::vector<ParamSpec>(MakeTable());
  return *kSpecs;
}


const ParamSpec* FindPipelineParam(absl::string_view name) {
  for (const ParamSpec& spec : PipelineParamSpecs()) {
    if (spec.name == name) return &spec;
  }
  return nullptr;
}

bool IsPipelineParamName(absl::string_view name) {
  if (FindPipelineParam(name) != nullptr) return true;
  const std::size_t dot = name.find('.');
  if (dot == absl::string_view::npos) return false;
  const ParamSpec* spec = FindPipelineParam(name.substr(dot + 1));
  return ParseFeatureMethod(name.substr(0, dot)).ok() && spec != nullptr &&
         spec->scope != Scope::kCollection && spec->name != "method";
}

}  // namespace meshseek
