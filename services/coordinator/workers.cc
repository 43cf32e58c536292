#include "services/coordinator/workers.h"

#include <algorithm>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "common/base/status_macros.h"
#include "common/bof/histogram_weighting.h"
#include "common/wire/convert.h"

namespace meshseek {

std::string CollectionPlan::build() const {
  const std::size_t at = codebook_id.rfind('@');
  return at == std::string::npos ? "" : codebook_id.substr(at + 1);
}

std::vector<std::string> CollectionPlan::PartNames() const {
  std::vector<std::string> names;
  for (const CollectionInfo& part : parts) names.push_back(part.name);
  return names;
}

std::string MemberCollectionName(const std::string& fused, FeatureMethod method) {
  return absl::StrCat(fused, "~", FeatureMethodName(method));
}

bool IsMemberCollection(const std::string& name) { return name.find('~') != std::string::npos; }

absl::StatusOr<CollectionPlan> LoadCollectionPlan(CoordinatorStore* store,
                                                  const std::string& name) {
  MESHSEEK_ASSIGN_OR_RETURN(StoredCollection stored, store->GetCollection(name));
  CollectionPlan plan;
  plan.name = name;
  plan.params = std::move(stored.params);
  plan.codebook_id = std::move(stored.codebook_id);
  plan.member = IsMemberCollection(name);
  MESHSEEK_ASSIGN_OR_RETURN(plan.options, wire::CollectionOptionsFromParams(plan.params));
  // Stored parameters are complete, so one without histogram_power was
  // created before histograms could be weighted: its index holds them
  // unweighted, and so must its queries be (LSF's default is 0.5 now).
  const bool before_weighting =
      std::none_of(plan.params.values().begin(), plan.params.values().end(),
                   [](const v1::ParamValue& v) {
                     // "histogram_power", or a fused collection's "lsf.histogram_power".
                     return absl::EndsWith(v.name(), "histogram_power");
                   });
  if (before_weighting) {
    for (RetrievalPipelineOptions& method : plan.options.methods) method.weighting = {};
  }
  if (!plan.fused()) {
    CollectionInfo part;
    part.name = name;
    part.options = plan.options.methods.front();
    wire::PipelineParamsToProto(part.options, &part.params);
    part.codebook_id = plan.codebook_id;
    plan.parts.push_back(std::move(part));
    return plan;
  }
  for (const RetrievalPipelineOptions& method : plan.options.methods) {
    const std::string member = MemberCollectionName(name, method.extractor.method);
    MESHSEEK_ASSIGN_OR_RETURN(StoredCollection part_stored, store->GetCollection(member));
    CollectionInfo part;
    part.name = member;
    part.options = method;
    wire::PipelineParamsToProto(method, &part.params);
    part.codebook_id = std::move(part_stored.codebook_id);
    plan.parts.push_back(std::move(part));
  }
  return plan;
}

absl::StatusOr<CollectionInfo> OnlyPart(const CollectionPlan& plan) {
  if (plan.fused()) {
    return absl::FailedPreconditionError(
        absl::StrCat("collection '", plan.name, "' fuses ", plan.options.MethodName()));
  }
  return plan.parts.front();
}

Workers::Workers(const CoordinatorOptions& options, const std::atomic<bool>* stop)
    : options_(options), stop_(stop) {
  retry_.attempts = options.call_attempts;
  rpc::ChannelOptions channel;
  channel.max_message_bytes = options.max_message_bytes;
  channel.credentials = options.service_credentials;
  channel.tls_server_name = options.service_tls_name;
  auto connect = [&](const std::string& target, const char* service) {
    channel.retry_service = service;
    return rpc::MakeChannel(target, channel);
  };
  resample_ = v1::Resample::NewStub(connect(options.resample_target, "meshseek.v1.Resample"));
  extract_ = v1::Extract::NewStub(connect(options.extract_target, "meshseek.v1.Extract"));
  codebook_ = v1::Codebook::NewStub(connect(options.codebook_target, "meshseek.v1.Codebook"));
  index_ = std::make_unique<IndexShards>(*IndexShards::ParseTargets(options.index_target), channel,
                                         options.call_deadline, retry_, stop);
}

absl::StatusOr<v1::LocalFeatures> Workers::Extract(const v1::Mesh& mesh,
                                                   const CollectionInfo& collection,
                                                   const std::string& model_id,
                                                   uint32_t threads) {
  v1::ExtractRequest request;
  *request.mutable_mesh()->mutable_mesh() = mesh;
  *request.mutable_params() = collection.params;
  request.set_model_id(model_id);
  request.set_threads(threads);
  if (collection.options.extractor.method == FeatureMethod::kRldSift) {
    v1::ResampleRequest resample;
    *resample.mutable_mesh()->mutable_mesh() = mesh;
    resample.set_num_samples(collection.options.extractor.rld.num_samples);
    resample.set_neighbors(collection.options.extractor.rld.neighbors);
    v1::ResampleResponse resampled;
    MESHSEEK_RETURN_IF_ERROR(rpc::CallWithRetry(resample_.get(), &v1::Resample::Stub::Resample,
                                                resample, &resampled, options_.extract_deadline,
                                                retry_, stop_));
    *request.mutable_resampled() = std::move(*resampled.mutable_graph());
  }
  v1::ExtractResponse response;
  MESHSEEK_RETURN_IF_ERROR(rpc::CallWithRetry(extract_.get(), &v1::Extract::Stub::Extract, request,
                                              &response, options_.extract_deadline, retry_, stop_));
  return std::move(*response.mutable_features());
}

absl::StatusOr<IndexSignature> Workers::Encode(const CollectionInfo& collection,
                                               const std::string& codebook_id,
                                               const v1::LocalFeatures& features,
                                               uint32_t threads) {
  IndexSignature signature;
  const FeatureMethod method = collection.options.extractor.method;
  if (FeatureMethodInfoOf(method).kind == DescriptorKind::kGlobal) {
    if (features.count() != 1 || features.descriptors().size() != features.dimension()) {
      return absl::DataLossError(absl::StrCat("features of ",
                                              features.count(),
                                              " descriptors of ",
                                              features.dimension(),
                                              " bytes, not one global ",
                                              FeatureMethodName(method),
                                              " descriptor"));
    }
    signature.descriptor.emplace();
    signature.descriptor->set_method(FeatureMethodName(method));
    signature.descriptor->set_data(features.descriptors());
    return signature;
  }
  v1::EncodeRequest request;
  request.set_codebook_id(codebook_id);
  request.set_threads(threads);
  *request.mutable_features() = features;
  v1::EncodeResponse response;
  MESHSEEK_RETURN_IF_ERROR(rpc::CallWithRetry(codebook_.get(), &v1::Codebook::Stub::Encode, request,
                                              &response, options_.call_deadline, retry_, stop_));
  signature.histogram = std::move(*response.mutable_histogram());
  // Power normalisation needs nothing but the histogram: its non-zero bins in
  // order, as the in-process pipeline weights the dense one (same values,
  // same sum). idf collections are refused at creation.
  const HistogramWeighting& weighting = collection.options.weighting;
  if (weighting.idf) {
    return absl::FailedPreconditionError("idf weighting is not served (collection refused)");
  }
  if (weighting.enabled()) {
    MESHSEEK_RETURN_IF_ERROR(
        WeightHistogram(weighting,
                        {},
                        absl::MakeSpan(signature.histogram.mutable_weights()->mutable_data(),
                                       signature.histogram.weights_size())));
  }
  return signature;
}

absl::Status Workers::AddToIndex(const std::string& collection,
                                 const std::string& model_id,
                                 uint64_t ordinal,
                                 const std::string& label,
                                 const IndexSignature& signature) {
  v1::AddModelRequest request;
  request.set_collection(collection);
  request.set_model_id(model_id);
  request.set_ordinal(ordinal);
  request.set_label(label);
  if (signature.descriptor.has_value()) {
    *request.mutable_global_descriptor() = *signature.descriptor;
  } else {
    *request.mutable_histogram() = signature.histogram;
  }
  return index_->Add(request);
}

absl::StatusOr<v1::LocalFeatures> Workers::FeaturesOf(CoordinatorStore* store,
                                                     const CollectionInfo& part,
                                                     const ExtractedModel& model) {
  // Intact stored features that do not parse are of a release we do not
  // know: extracted again like freed ones.
  v1::LocalFeatures features;
  if (const std::optional<std::string> stored = store->LoadFeatures({part.name, model.model_id});
      stored.has_value() && features.ParseFromString(*stored)) {
    return features;
  }
  MESHSEEK_ASSIGN_OR_RETURN(const std::optional<std::string> stored,
                            store->ModelMesh({part.name, model.model_id}));
  v1::Mesh mesh;
  if (!stored.has_value() || !mesh.ParseFromString(*stored)) {
    return absl::DataLossError(
        absl::StrCat("model ", model.model_id, ": no stored mesh to extract its features from"));
  }
  return Extract(mesh, part, model.model_id);
}

}  // namespace meshseek
