// The extract service as gRPC serves it: each generated entry point is one call
// of rpc::Serve (common/rpc/handler.h) with the handler of ExtractService, so
// the service itself knows nothing of gRPC and its handlers are tested as
// functions.
#ifndef MESHSEEK_SERVICES_EXTRACT_EXTRACT_GRPC_H_
#define MESHSEEK_SERVICES_EXTRACT_EXTRACT_GRPC_H_

#include "common/rpc/handler.h"
#include "meshseek/v1/extract.grpc.pb.h"
#include "services/extract/extract_service.h"

namespace meshseek {

class ExtractGrpc final : public v1::Extract::Service {
 public:
  /// `service` is not owned and outlives this.
  explicit ExtractGrpc(ExtractService* service) : service_(service) {}

  grpc::Status Extract(grpc::ServerContext* context,
                       const v1::ExtractRequest* request,
                       v1::ExtractResponse* response) override {
    return rpc::Serve(context, request, response, service_, &ExtractService::Extract);
  }

 private:
  ExtractService* const service_;
};

}  // namespace meshseek

#endif  // MESHSEEK_SERVICES_EXTRACT_EXTRACT_GRPC_H_
