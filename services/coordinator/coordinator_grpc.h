// The coordinator service as gRPC serves it: each generated entry point is one call
// of rpc::Serve (common/rpc/handler.h) with the handler of CoordinatorService, so
// the service itself knows nothing of gRPC and its handlers are tested as
// functions.
#ifndef MESHSEEK_SERVICES_COORDINATOR_COORDINATOR_GRPC_H_
#define MESHSEEK_SERVICES_COORDINATOR_COORDINATOR_GRPC_H_

#include "common/rpc/handler.h"
#include "meshseek/v1/coordinator.grpc.pb.h"
#include "services/coordinator/coordinator_service.h"

namespace meshseek {

class CoordinatorGrpc final : public v1::Coordinator::Service {
 public:
  /// `service` is not owned and outlives this.
  explicit CoordinatorGrpc(CoordinatorService* service) : service_(service) {}

  grpc::Status CreateCollection(grpc::ServerContext* context,
                                const v1::CreateCollectionRequest* request,
                                v1::Collection* response) override {
    return rpc::Serve(context, request, response, service_, &CoordinatorService::CreateCollection);
  }
  grpc::Status GetCollection(grpc::ServerContext* context,
                             const v1::GetCollectionRequest* request,
                             v1::Collection* response) override {
    return rpc::Serve(context, request, response, service_, &CoordinatorService::GetCollection);
  }
  grpc::Status Ingest(grpc::ServerContext* context,
                      grpc::ServerReaderWriter<v1::IngestAck, v1::IngestRequest>* stream) override {
    return rpc::Serve(context, stream, service_, &CoordinatorService::Ingest);
  }
  grpc::Status Build(grpc::ServerContext* context,
                     const v1::BuildRequest* request,
                     v1::JobStatus* response) override {
    return rpc::Serve(context, request, response, service_, &CoordinatorService::Build);
  }
  grpc::Status GetJob(grpc::ServerContext* context,
                      const v1::JobRequest* request,
                      v1::JobStatus* response) override {
    return rpc::Serve(context, request, response, service_, &CoordinatorService::GetJob);
  }
  grpc::Status WatchJob(grpc::ServerContext* context,
                        const v1::JobRequest* request,
                        grpc::ServerWriter<v1::JobStatus>* writer) override {
    return rpc::Serve(context, request, writer, service_, &CoordinatorService::WatchJob);
  }
  grpc::Status Query(grpc::ServerContext* context,
                     const v1::QueryRequest* request,
                     v1::QueryResponse* response) override {
    return rpc::Serve(context, request, response, service_, &CoordinatorService::Query);
  }
  grpc::Status QueryByImage(grpc::ServerContext* context,
                            const v1::QueryByImageRequest* request,
                            v1::QueryResponse* response) override {
    return rpc::Serve(context, request, response, service_, &CoordinatorService::QueryByImage);
  }
  grpc::Status RemoveModel(grpc::ServerContext* context,
                           const v1::RemoveModelFromCollectionRequest* request,
                           v1::RemoveModelFromCollectionResponse* response) override {
    return rpc::Serve(context, request, response, service_, &CoordinatorService::RemoveModel);
  }
  grpc::Status ListModels(grpc::ServerContext* context,
                          const v1::ListCollectionModelsRequest* request,
                          v1::ListCollectionModelsResponse* response) override {
    return rpc::Serve(context, request, response, service_, &CoordinatorService::ListModels);
  }
  grpc::Status ListCollections(grpc::ServerContext* context,
                               const v1::ListCollectionsRequest* request,
                               v1::ListCollectionsResponse* response) override {
    return rpc::Serve(context, request, response, service_, &CoordinatorService::ListCollections);
  }
  grpc::Status GetThumbnail(grpc::ServerContext* context,
                            const v1::GetThumbnailRequest* request,
                            v1::Thumbnail* response) override {
    return rpc::Serve(context, request, response, service_, &CoordinatorService::GetThumbnail);
  }
  grpc::Status Evaluate(grpc::ServerContext* context,
                        const v1::EvaluateRequest* request,
                        grpc::ServerWriter<v1::EvaluateRow>* writer) override {
    return rpc::Serve(context, request, writer, service_, &CoordinatorService::Evaluate);
  }

 private:
  CoordinatorService* const service_;
};

}  // namespace meshseek

#endif  // MESHSEEK_SERVICES_COORDINATOR_COORDINATOR_GRPC_H_
