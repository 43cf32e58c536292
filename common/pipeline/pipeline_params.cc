#include "common/pipeline/pipeline_params.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <optional>
#include <set>

#include "absl/strings/match.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_split.h"
#include "common/base/status_macros.h"
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

// Canonical text of a value: integers in full, doubles shortest round-trip.
std::string Text(int v) { return absl::StrCat(v); }
std::string Text(uint64_t v) { return absl::StrCat(v); }
std::string Text(bool v) { return v ? "true" : "false"; }
std::string Text(double v);
std::string Text(const std::vector<double>& v) {
  std::string out;
  for (double x : v) absl::StrAppend(&out, out.empty() ? "" : ",", Text(x));
  return out;
}
std::string Text(double v) {
  // Six significant digits when they read back to the same double (every
  // default), all seventeen otherwise.
  std::string text = absl::StrCat(v);
  if (std::strtod(text.c_str(), nullptr) == v) return text;
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.17g", v);
  return buffer;
}

template <typename T>
ParamType TypeOf();
template <>
ParamType TypeOf<int>() {
  return ParamType::kInt;
}
template <>
ParamType TypeOf<uint64_t>() {
  return ParamType::kUint64;
}
template <>
ParamType TypeOf<double>() {
  return ParamType::kDouble;
}
template <>
ParamType TypeOf<bool>() {
  return ParamType::kBool;
}
template <>
ParamType TypeOf<std::vector<double>>() {
  return ParamType::kDoubleList;
}

void Parse(absl::string_view text, int* v) { (void)absl::SimpleAtoi(text, v); }
void Parse(absl::string_view text, uint64_t* v) { (void)absl::SimpleAtoi(text, v); }
void Parse(absl::string_view text, double* v) { (void)absl::SimpleAtod(text, v); }
void Parse(absl::string_view text, bool* v) { *v = text == "true"; }
void Parse(absl::string_view text, std::vector<double>* v) {
  v->clear();
  for (absl::string_view part : absl::StrSplit(text, ',', absl::SkipEmpty())) {
    double x = 0;
    (void)absl::SimpleAtod(part, &x);
    v->push_back(x);
  }
}

// A parameter stored in one field of the selected method's options: `field`
// returns that field (it may look at options.extractor.method).
template <typename T>
ParamSpec Field(std::string name,
                std::string doc,
                double min,
                double max,
                Scope scope,
                std::vector<FeatureMethod> methods,
                T& (*field)(Options&)) {
  ParamSpec spec;
  spec.name = std::move(name);
  spec.type = TypeOf<T>();
  spec.doc = std::move(doc);
  spec.min = min;
  spec.max = max;
  spec.scope = scope;
  spec.methods = std::move(methods);
  spec.get = [field](const Options& o) { return Text(field(const_cast<Options&>(o))); };
  spec.set = [field](absl::string_view text, Options* o) { Parse(text, &field(*o)); };
  return spec;
}

// A parameter with named values stored as an enumerator.
template <typename E>
ParamSpec Choice(std::string name,
                 std::string doc,
                 Scope scope,
                 std::vector<FeatureMethod> methods,
                 E& (*field)(Options&),
                 std::vector<std::pair<std::string, E>> values) {
  ParamSpec spec;
  spec.name = std::move(name);
  spec.type = ParamType::kChoice;
  spec.doc = std::move(doc);
  spec.scope = scope;
  spec.methods = std::move(methods);
  for (const auto& [text, value] : values) spec.choices.push_back(text);
  spec.get = [field, values](const Options& o) {
    const E current = field(const_cast<Options&>(o));
    for (const auto& [text, value] : values) {
      if (value == current) return text;
    }
    return std::string("?");
  };
  spec.set = [field, values](absl::string_view text, Options* o) {
    for (const auto& [name, value] : values) {
      if (name == text) field(*o) = value;
    }
  };
  return spec;
}

// A parameter of the collection (fusion, re-ranking) stored in one field.
template <typename T>
ParamSpec CollectionField(
    std::string name, std::string doc, double min, double max, T& (*field)(CollectionOptions&)) {
  ParamSpec spec;
  spec.name = std::move(name);
  spec.type = TypeOf<T>();
  spec.doc = std::move(doc);
  spec.min = min;
  spec.max = max;
  spec.scope = Scope::kCollection;
  spec.collection_get = [field](const CollectionOptions& o) {
    return Text(field(const_cast<CollectionOptions&>(o)));
  };
  spec.collection_set = [field](absl::string_view text, CollectionOptions* o) {
    Parse(text, &field(*o));
  };
  return spec;
}

// The sub-options every SIFT method has, of the selected method.
DepthImageOptions& DepthImage(Options& o) {
  switch (o.extractor.method) {
    case kLd:
      return o.extractor.ld.depth_image;
    case kRld:
      return o.extractor.rld.depth_image;
    case kBf:
      return o.extractor.bfdsift.patch_image;
    default:
      return o.extractor.dld.depth_image;
  }
}
SiftDescriptorOptions& Sift(Options& o) {
  switch (o.extractor.method) {
    case kLd:
      return o.extractor.ld.descriptor;
    case kRld:
      return o.extractor.rld.descriptor;
    case kBf:
      return o.extractor.bfdsift.descriptor;
    default:
      return o.extractor.dld.descriptor;
  }
}
ScaleSpaceOptions& ScaleSpace(Options& o) {
  return o.extractor.method == kLd ? o.extractor.ld.scale_space : o.extractor.rld.scale_space;
}

std::vector<ParamSpec> MakeSpecs() {
  std::vector<ParamSpec> specs;
  {
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
    method.get = [](const Options& o) {
      return std::string(FeatureMethodName(o.extractor.method));
    };
    method.set = [](absl::string_view text, Options* o) {
      *o = Options::ForMethod(*ParseFeatureMethod(text));
    };
    specs.push_back(std::move(method));
  }
  const Scope listed = Scope::kListed;
  specs.push_back(Field<double>(
      "scale",
      "support radius E relative to the minimum enclosing sphere (s = E * D / 2)",
      1e-6,
      2,
      listed,
      {kDld, kLsf},
      +[](Options& o) -> double& {
        return o.extractor.method == kLsf ? o.extractor.lsf.scale : o.extractor.dld.scale;
      }));
  specs.push_back(Field<int>(
      "points",
      "feature points per model (N_DLD, LSF's centres)",
      1,
      1000000,
      listed,
      {kDld, kLsf},
      +[](Options& o) -> int& {
        return o.extractor.method == kLsf ? o.extractor.lsf.num_points : o.extractor.dld.num_points;
      }));
  specs.push_back(Field<std::vector<double>>(
      "extra_scales",
      "further support radii (as scale), every centre described at each",
      1e-6,
      2,
      listed,
      {kLsf},
      +[](Options& o) -> std::vector<double>& { return o.extractor.lsf.extra_scales; }));
  specs.push_back(Field<int>(
      "samples_per_support",
      "oriented surface samples in a flat disc of the support radius",
      8,
      100000,
      listed,
      {kLsf},
      +[](Options& o) -> int& { return o.extractor.lsf.samples_per_support; }));
  specs.push_back(Field<int>(
      "distance_bins",
      "histogram bins over the distance to the centre",
      1,
      64,
      listed,
      {kLsf},
      +[](Options& o) -> int& { return o.extractor.lsf.distance_bins; }));
  specs.push_back(Field<int>(
      "angle_bins",
      "histogram bins over each normal angle",
      1,
      64,
      listed,
      {kLsf},
      +[](Options& o) -> int& { return o.extractor.lsf.angle_bins; }));
  specs.push_back(Field<int>(
      "frame_samples",
      "dense surface samples per support disc for the local PCA frame",
      8,
      1000000,
      listed,
      {kDld},
      +[](Options& o) -> int& { return o.extractor.dld.frame_samples_per_support; }));
  specs.push_back(Field<double>(
      "frame_radius",
      "the local frame uses the samples within this many support radii",
      0.25,
      4,
      listed,
      {kDld},
      +[](Options& o) -> double& { return o.extractor.dld.frame_radius_factor; }));
  specs.push_back(Field<bool>(
      "weighted_frame",
      "distance-weighted (SHOT-style) PCA frame instead of plain PCA",
      0,
      1,
      listed,
      {kDld, kRld},
      +[](Options& o) -> bool& {
        return o.extractor.method == kRld ? o.extractor.rld.weighted_frame
                                          : o.extractor.dld.weighted_frame;
      }));
  specs.push_back(Field<int>(
      "rld_samples",
      "resample points (N_RLD)",
      100,
      10000000,
      listed,
      {kRld},
      +[](Options& o) -> int& { return o.extractor.rld.num_samples; }));
  specs.push_back(Field<int>(
      "rld_neighbors",
      "k of the k-nearest-neighbour graph",
      1,
      100,
      listed,
      {kRld},
      +[](Options& o) -> int& { return o.extractor.rld.neighbors; }));
  specs.push_back(Field<int>(
      "levels", "scale-space levels L", 2, 200, listed, {kLd, kRld}, +[](Options& o) -> int& {
        return ScaleSpace(o).levels;
      }));
  specs.push_back(Field<double>(
      "scale_factor",
      "C in the feature scale s = C * d * sqrt(level)",
      1e-6,
      1e6,
      listed,
      {kLd, kRld},
      +[](Options& o) -> double& { return ScaleSpace(o).scale_factor; }));
  specs.push_back(Field<int>(
      "view_level",
      "view directions: vertices of the icosahedron subdivided this often (1: 42)",
      0,
      3,
      listed,
      {kBf},
      +[](Options& o) -> int& { return o.extractor.bfdsift.view_level; }));
  specs.push_back(Field<int>(
      "view_size",
      "side of each whole-model view in pixels",
      32,
      1024,
      listed,
      {kBf, kLfd},
      +[](Options& o) -> int& {
        return o.extractor.method == kLfd ? o.extractor.lfd.image_size
                                          : o.extractor.bfdsift.view_size;
      }));
  specs.push_back(Field<int>(
      "contour_samples",
      "points the silhouette's outer contour is resampled to (Fourier)",
      21,
      65536,
      listed,
      {kLfd},
      +[](Options& o) -> int& { return o.extractor.lfd.contour_samples; }));
  specs.push_back(Choice<LfdZernikeRadius>(
      "zernike_radius",
      "Zernike disc radius: per view | per light field (the original's)",
      listed,
      {kLfd},
      +[](Options& o) -> LfdZernikeRadius& { return o.extractor.lfd.zernike_radius; },
      {{"view", LfdZernikeRadius::kPerView}, {"lightfield", LfdZernikeRadius::kPerLightField}}));
  specs.push_back(Field<int>(
      "points_per_view",
      "dense grid points per view inside the silhouette",
      1,
      100000,
      listed,
      {kBf},
      +[](Options& o) -> int& { return o.extractor.bfdsift.points_per_view; }));
  specs.push_back(Field<double>(
      "patch_radius",
      "smallest SIFT patch radius relative to the view's side",
      1e-3,
      0.5,
      listed,
      {kBf},
      +[](Options& o) -> double& { return o.extractor.bfdsift.patch_radius; }));
  specs.push_back(Field<int>(
      "patch_scales",
      "patch radii per point: patch_radius, twice it, ...",
      1,
      4,
      listed,
      {kBf},
      +[](Options& o) -> int& { return o.extractor.bfdsift.patch_scales; }));
  specs.push_back(Field<int>(
      "image_size",
      "local depth image side I in pixels (odd)",
      3,
      255,
      listed,
      {kDld, kLd, kRld, kBf},
      +[](Options& o) -> int& { return DepthImage(o).image_size; }));
  specs.push_back(Choice<ImageOrientation>(
      "orientation",
      "descriptor rotation: Lowe's gradient peaks | PCA up axis + 180-degree sum",
      listed,
      {kDld, kLd, kRld, kBf},
      +[](Options& o) -> ImageOrientation& { return Sift(o).orientation; },
      {{"dominant", ImageOrientation::kDominant}, {"up", ImageOrientation::kUpAxis}}));
  specs.push_back(Choice<DepthToGray>(
      "depth_to_gray",
      "depth to grey: fixed (2s range) | stretch (image range)",
      listed,
      {kDld, kLd, kRld, kBf},
      +[](Options& o) -> DepthToGray& { return Sift(o).depth_to_gray; },
      {{"fixed", DepthToGray::kFixedRange}, {"stretch", DepthToGray::kStretch}}));
  specs.push_back(Field<int>(
      "max_orientations",
      "with dominant orientation: at most this many descriptors per image (0: every peak within "
      "80 % of the highest)",
      0,
      36,
      listed,
      {kDld, kLd, kRld, kBf},
      +[](Options& o) -> int& { return Sift(o).max_orientations; }));
  specs.push_back(Field<double>(
      "blur_sigma",
      "SIFT blur sigma in pixels",
      0.5,
      5,
      listed,
      {kDld, kLd, kRld, kBf},
      +[](Options& o) -> double& { return Sift(o).blur_sigma; }));
  const Scope bag = Scope::kBagOfFeatures;
  specs.push_back(Field<int>(
      "vocabulary",
      "codebook size V (k-means centroids)",
      1,
      static_cast<double>(kMaxVocabulary),
      bag,
      {},
      +[](Options& o) -> int& { return o.kmeans.num_centroids; }));
  specs.push_back(Field<int>(
      "kmeans_points_per_centroid",
      "k-means trains on at most this many features per centroid",
      1,
      1000000,
      bag,
      {},
      +[](Options& o) -> int& { return o.kmeans.max_points_per_centroid; }));
  specs.push_back(Field<int>(
      "kmeans_iterations",
      "maximum k-means iterations",
      1,
      10000,
      bag,
      {},
      +[](Options& o) -> int& { return o.kmeans.max_iterations; }));
  specs.push_back(Choice<KMeansOptions::Assignment>(
      "kmeans_assignment",
      "nearest-word search of k-means and encoding: auto (exact below V = 1,000, approximate "
      "from there) | exact | approximate",
      bag,
      {},
      +[](Options& o) -> KMeansOptions::Assignment& { return o.kmeans.assignment; },
      {{"auto", KMeansOptions::Assignment::kAuto},
       {"exact", KMeansOptions::Assignment::kExact},
       {"approximate", KMeansOptions::Assignment::kApproximate}}));
  specs.push_back(Field<uint64_t>(
      "seed",
      "seed of k-means sampling and seeding",
      0,
      static_cast<double>(std::numeric_limits<uint64_t>::max()),
      bag,
      {},
      +[](Options& o) -> uint64_t& { return o.kmeans.seed; }));
  specs.push_back(Field<bool>(
      "idf",
      "weight histogram words by inverse document frequency over the collection (tf-idf)",
      0,
      1,
      bag,
      {},
      +[](Options& o) -> bool& { return o.weighting.idf; }));
  specs.push_back(Field<double>(
      "histogram_power",
      "raise histogram bins to this power before ranking (0.5: square root; 1: none)",
      0.01,
      1,
      bag,
      {},
      +[](Options& o) -> double& { return o.weighting.power; }));
  specs.push_back(Field<double>(
      "kl_epsilon",
      "mass added to every histogram bin before KL divergence (zero-bin rule)",
      1e-30,
      0.5,
      bag,
      {},
      +[](Options& o) -> double& { return o.kl.epsilon; }));

  // The collection's: how the methods' distances become one ranking.
  specs.push_back(CollectionField<std::vector<double>>(
      "weights",
      "fusion weight of each method, in the order named (several methods)",
      0,
      1000,
      +[](CollectionOptions& o) -> std::vector<double>& { return o.weights; }));
  {
    ParamSpec rerank;
    rerank.name = "rerank";
    rerank.type = ParamType::kChoice;
    rerank.scope = Scope::kCollection;
    rerank.doc =
        "re-ranking over the collection's neighbour graph: none | kreciprocal (k-reciprocal "
        "encoding)";
    rerank.choices = {"none", "kreciprocal"};
    rerank.collection_get = [](const CollectionOptions& o) {
      return std::string(o.rerank.enabled() ? "kreciprocal" : "none");
    };
    rerank.collection_set = [](absl::string_view text, CollectionOptions* o) {
      o->rerank.method = text == "kreciprocal" ? RerankOptions::Method::kKReciprocal
                                               : RerankOptions::Method::kNone;
    };
    specs.push_back(std::move(rerank));
  }
  specs.push_back(CollectionField<int>(
      "rerank_k1",
      "re-ranking: neighbourhood whose reciprocal members describe a model",
      1,
      NeighborGraph::kMaxK - 1,
      +[](CollectionOptions& o) -> int& { return o.rerank.k1; }));
  specs.push_back(CollectionField<int>(
      "rerank_k2",
      "re-ranking: nearest models averaged in local query expansion (1: none)",
      1,
      NeighborGraph::kMaxK,
      +[](CollectionOptions& o) -> int& { return o.rerank.k2; }));
  specs.push_back(CollectionField<double>(
      "rerank_lambda",
      "re-ranking: weight of the original distance",
      0,
      1,
      +[](CollectionOptions& o) -> double& { return o.rerank.lambda; }));
  specs.push_back(CollectionField<int>(
      "rerank_depth",
      "re-ranking: models re-ranked per query",
      1,
      100000,
      +[](CollectionOptions& o) -> int& { return o.rerank.depth; }));
  return specs;
}

// Parses and range-checks `text` as the spec's type.
absl::Status CheckValue(const ParamSpec& spec, absl::string_view text) {
  auto bad = [&]() {
    return absl::InvalidArgumentError(
        absl::StrCat("parameter ", spec.name, ": '", text, "' is not ", spec.TypeDescription()));
  };
  switch (spec.type) {
    case ParamType::kInt: {
      int v;
      if (!absl::SimpleAtoi(text, &v) || v < spec.min || v > spec.max) return bad();
      return absl::OkStatus();
    }
    case ParamType::kUint64: {
      uint64_t v;
      if (!absl::SimpleAtoi(text, &v) || static_cast<double>(v) < spec.min) return bad();
      return absl::OkStatus();
    }
    case ParamType::kDouble: {
      double v;
      if (!absl::SimpleAtod(text, &v) || !std::isfinite(v) || v < spec.min || v > spec.max) {
        return bad();
      }
      return absl::OkStatus();
    }
    case ParamType::kBool:
      if (text != "true" && text != "false") return bad();
      return absl::OkStatus();
    case ParamType::kChoice:
      for (const std::string& choice : spec.choices) {
        if (choice == text) return absl::OkStatus();
      }
      return bad();
    case ParamType::kDoubleList: {
      int count = 0;
      for (absl::string_view part : absl::StrSplit(text, ',', absl::SkipEmpty())) {
        double v;
        if (++count > 8 || !absl::SimpleAtod(part, &v) || !std::isfinite(v) || v < spec.min ||
            v > spec.max) {
          return bad();
        }
      }
      return absl::OkStatus();
    }
  }
  return bad();
}

std::string MethodNames(const ParamSpec& spec) {
  switch (spec.scope) {
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
  for (FeatureMethod m : spec.methods) names.push_back(FeatureMethodName(m));
  return absl::StrJoin(names, ", ");
}

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
      return absl::StrCat("a number in [", Text(min), ", ", Text(max), "]");
    case ParamType::kBool:
      return "true or false";
    case ParamType::kChoice:
      return absl::StrCat("one of ", absl::StrJoin(choices, ", "));
    case ParamType::kDoubleList:
      return absl::StrCat("up to 8 comma-separated numbers in [", Text(min), ", ", Text(max), "]");
  }
  return "?";
}

const std::vector<ParamSpec>& PipelineParamSpecs() {
  static const auto* const kSpecs = new std::vector<ParamSpec>(MakeSpecs());
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

absl::StatusOr<CollectionOptions> CollectionOptionsFromValues(const ParamValues& values) {
  // The methods decide every other parameter's default and meaning.
  std::string method_list = FeatureMethodName(FeatureMethod::kDldSift);
  for (const auto& [name, value] : values) {
    if (name == "method") method_list = value;
  }
  const ParamSpec& method_spec = PipelineParamSpecs().front();
  std::vector<FeatureMethod> methods;
  for (absl::string_view name : absl::StrSplit(method_list, '+')) {
    MESHSEEK_RETURN_IF_ERROR(CheckValue(method_spec, name));
    const FeatureMethod m = *ParseFeatureMethod(name);
    if (std::find(methods.begin(), methods.end(), m) != methods.end()) {
      return absl::InvalidArgumentError(
          absl::StrCat("parameter method: '", name, "' is named twice in '", method_list, "'"));
    }
    methods.push_back(m);
  }
  if (methods.size() > CollectionOptions::kMaxMethods) {
    return absl::InvalidArgumentError(absl::StrCat("parameter method: at most ",
                                                   CollectionOptions::kMaxMethods,
                                                   " methods, got ",
                                                   methods.size()));
  }
  CollectionOptions options = CollectionOptions::ForMethods(methods);
  for (const auto& [name, value] : values) {
    if (name == "method") continue;
    // "rld.vocabulary": one method's; "vocabulary": every method's it applies to.
    absl::string_view plain = name;
    std::optional<FeatureMethod> only;
    if (const std::size_t dot = plain.find('.'); dot != absl::string_view::npos) {
      absl::StatusOr<FeatureMethod> m = ParseFeatureMethod(plain.substr(0, dot));
      if (!m.ok()) {
        return absl::InvalidArgumentError(
            absl::StrCat("parameter ", name, ": ", m.status().message()));
      }
      if (std::find(methods.begin(), methods.end(), *m) == methods.end()) {
        return absl::InvalidArgumentError(absl::StrCat("parameter ",
                                                       name,
                                                       ": method ",
                                                       plain.substr(0, dot),
                                                       " is not in '",
                                                       method_list,
                                                       "'"));
      }
      only = *m;
      plain = plain.substr(dot + 1);
    }
    const ParamSpec* spec = FindPipelineParam(plain);
    if (spec == nullptr || spec->name == "method" ||
        (only.has_value() && spec->scope == Scope::kCollection)) {
      std::vector<std::string> known;
      for (const ParamSpec& s : PipelineParamSpecs()) known.push_back(s.name);
      return absl::InvalidArgumentError(
          absl::StrCat("unknown parameter '",
                       name,
                       "' (known: ",
                       absl::StrJoin(known, ", "),
                       "; a method's may be qualified: rld.vocabulary)"));
    }
    MESHSEEK_RETURN_IF_ERROR(CheckValue(*spec, value));
    if (spec->scope == Scope::kCollection) {
      spec->collection_set(value, &options);
      continue;
    }
    bool applied = false;
    for (RetrievalPipelineOptions& m : options.methods) {
      const FeatureMethod method = m.extractor.method;
      if ((only.has_value() && method != *only) || !spec->AppliesTo(method)) continue;
      spec->set(value, &m);
      applied = true;
    }
    if (!applied) {
      return absl::InvalidArgumentError(
          absl::StrCat("parameter ",
                       name,
                       " does not apply to method ",
                       only.has_value() ? FeatureMethodName(*only) : method_list.c_str(),
                       " (it applies to ",
                       MethodNames(*spec),
                       ")"));
    }
  }
  MESHSEEK_RETURN_IF_ERROR(options.Validate());
  return options;
}

ParamValues CollectionValuesOf(const CollectionOptions& options) {
  ParamValues values;
  values.emplace_back("method", options.MethodName());
  for (const RetrievalPipelineOptions& m : options.methods) {
    const std::string prefix =
        options.fused() ? absl::StrCat(FeatureMethodName(m.extractor.method), ".") : "";
    for (const ParamSpec& spec : PipelineParamSpecs()) {
      if (spec.name != "method" && spec.AppliesTo(m.extractor.method)) {
        values.emplace_back(prefix + spec.name, spec.get(m));
      }
    }
  }
  for (const ParamSpec& spec : PipelineParamSpecs()) {
    if (spec.scope != Scope::kCollection) continue;
    // Weights mean something with several methods; the re-ranking's own
    // parameters when it is on.
    if (spec.name == "weights" && !options.fused()) continue;
    if (absl::StartsWith(spec.name, "rerank_") && !options.rerank.enabled()) continue;
    values.emplace_back(spec.name, spec.collection_get(options));
  }
  return values;
}

absl::StatusOr<RetrievalPipelineOptions> PipelineOptionsFromValues(const ParamValues& values) {
  MESHSEEK_ASSIGN_OR_RETURN(const CollectionOptions options, CollectionOptionsFromValues(values));
  if (options.fused() || options.rerank.enabled()) {
    return absl::InvalidArgumentError(
        absl::StrCat("parameters of one method were expected, got '",
                     options.MethodName(),
                     "'",
                     options.rerank.enabled() ? " with re-ranking" : ""));
  }
  return options.methods.front();
}

ParamValues PipelineValuesOf(const RetrievalPipelineOptions& options) {
  return CollectionValuesOf(CollectionOptions::Of(options));
}

namespace {

// Sets json[spec.name] to `text` as the spec's type.
void SetTyped(const ParamSpec& spec, const std::string& text, Json* json) {
  switch (spec.type) {
    case ParamType::kInt:
    case ParamType::kUint64: {
      int64_t v = 0;
      if (absl::SimpleAtoi(text, &v)) {
        json->Set(spec.name, v);
      } else {
        json->Set(spec.name, text);  // a uint64 beyond int64: exact as text
      }
      break;
    }
    case ParamType::kDouble: {
      double v = 0;
      (void)absl::SimpleAtod(text, &v);
      json->Set(spec.name, v);
      break;
    }
    case ParamType::kBool:
      json->Set(spec.name, text == "true");
      break;
    case ParamType::kChoice:
      json->Set(spec.name, text);
      break;
    case ParamType::kDoubleList: {
      Json& list = json->Set(spec.name, Json::MakeArray());
      std::vector<double> values;
      Parse(text, &values);
      for (double v : values) list.Push(v);
      break;
    }
  }
}

}  // namespace

Json PipelineParamsToJson(const RetrievalPipelineOptions& options) {
  Json json = Json::MakeObject();
  for (const ParamSpec& spec : PipelineParamSpecs()) {
    if (spec.AppliesTo(options.extractor.method)) SetTyped(spec, spec.get(options), &json);
  }
  return json;
}

void AddCollectionParamsToJson(const CollectionOptions& options, Json* json) {
  for (const auto& [name, value] : CollectionValuesOf(options)) {
    const ParamSpec* spec = FindPipelineParam(name);
    if (spec != nullptr && spec->scope == Scope::kCollection) SetTyped(*spec, value, json);
  }
}

std::string PipelineParamsUsage() {
  std::string usage =
      "Pipeline parameters (--name=value; each applies to the methods named; with several\n"
      "methods, --rld.vocabulary=3000 sets one method's):\n";
  for (const ParamSpec& spec : PipelineParamSpecs()) {
    if (spec.scope == Scope::kCollection) {
      // Defaults for one method and for several (a fusion).
      const std::string one = spec.collection_get(CollectionOptions());
      const std::string several = spec.collection_get(
          CollectionOptions::ForMethods({FeatureMethod::kBfDsift, FeatureMethod::kRldSift}));
      std::string value =
          one == several ? one : absl::StrCat("one method ", one, ", several ", several);
      if (spec.name == "weights") {
        std::vector<std::string> own;
        for (const FeatureMethodInfo& m : FeatureMethods()) {
          own.push_back(absl::StrCat(m.name, " ", m.fusion_weight));
        }
        value = absl::StrCat("each method's own: ", absl::StrJoin(own, ", "));
      }
      absl::StrAppend(&usage,
                      "  --",
                      spec.name,
                      "  ",
                      spec.TypeDescription(),
                      "; ",
                      spec.doc,
                      "\n      the collection; default: ",
                      value,
                      "\n");
      continue;
    }
    // "default: 20" when every method has the same, else "default: rld 15, ld 20".
    std::vector<std::string> defaults;
    std::set<std::string> distinct;
    for (const FeatureMethodInfo& info : FeatureMethods()) {
      if (spec.name == "method" || !spec.AppliesTo(info.method)) continue;
      const std::string value = spec.get(Options::ForMethod(info.method));
      defaults.push_back(absl::StrCat(info.name, " ", value));
      distinct.insert(value);
    }
    if (distinct.size() == 1) defaults = {*distinct.begin()};
    absl::StrAppend(&usage, "  --", spec.name, "  ", spec.TypeDescription(), "; ", spec.doc, "\n");
    if (spec.name == "method") {
      absl::StrAppend(&usage, "      default: ", FeatureMethodName(FeatureMethod::kDldSift), "\n");
    } else {
      absl::StrAppend(
          &usage, "      ", MethodNames(spec), "; default: ", absl::StrJoin(defaults, ", "), "\n");
    }
  }
  return usage;
}

}  // namespace meshseek
