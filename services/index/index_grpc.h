// The index service as gRPC serves it: each generated entry point is one call
// of rpc::Serve (common/rpc/handler.h) with the handler of IndexService, so
// the service itself knows nothing of gRPC and its handlers are tested as
// functions.
#ifndef MESHSEEK_SERVICES_INDEX_INDEX_GRPC_H_
#define MESHSEEK_SERVICES_INDEX_INDEX_GRPC_H_

#include "common/rpc/handler.h"
#include "meshseek/v1/index.grpc.pb.h"
#include "services/index/index_service.h"

namespace meshseek {

class IndexGrpc final : public v1::Index::Service {
 public:
  /// `service` is not owned and outlives this.
  explicit IndexGrpc(IndexService* service) : service_(service) {}

  grpc::Status AddModel(grpc::ServerContext* context,
                        const v1::AddModelRequest* request,
                        v1::AddModelResponse* response) override {
    return rpc::Serve(context, request, response, service_, &IndexService::AddModel);
  }
  grpc::Status RemoveModel(grpc::ServerContext* context,
                           const v1::RemoveModelRequest* request,
                           v1::RemoveModelResponse* response) override {
    return rpc::Serve(context, request, response, service_, &IndexService::RemoveModel);
  }
  grpc::Status Search(grpc::ServerContext* context,
                      const v1::SearchRequest* request,
                      v1::SearchResponse* response) override {
    return rpc::Serve(context, request, response, service_, &IndexService::Search);
  }
  grpc::Status ExportModels(grpc::ServerContext* context,
                            const v1::ExportModelsRequest* request,
                            grpc::ServerWriter<v1::IndexedModel>* writer) override {
    return rpc::Serve(context, request, writer, service_, &IndexService::ExportModels);
  }
  grpc::Status Distances(grpc::ServerContext* context,
                         const v1::DistancesRequest* request,
                         v1::DistancesResponse* response) override {
    return rpc::Serve(context, request, response, service_, &IndexService::Distances);
  }
  grpc::Status ListModels(grpc::ServerContext* context,
                          const v1::ListModelsRequest* request,
                          v1::ListModelsResponse* response) override {
    return rpc::Serve(context, request, response, service_, &IndexService::ListModels);
  }
  grpc::Status Neighbors(grpc::ServerContext* context,
                         const v1::NeighborsRequest* request,
                         grpc::ServerWriter<v1::NeighborLists>* writer) override {
    return rpc::Serve(context, request, writer, service_, &IndexService::Neighbors);
  }
  grpc::Status PairDistances(grpc::ServerContext* context,
                             const v1::PairDistancesRequest* request,
                             v1::PairDistancesResponse* response) override {
    return rpc::Serve(context, request, response, service_, &IndexService::PairDistances);
  }

 private:
  IndexService* const service_;
};

}  // namespace meshseek

#endif  // MESHSEEK_SERVICES_INDEX_INDEX_GRPC_H_
