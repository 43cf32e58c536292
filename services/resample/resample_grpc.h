// The resample service as gRPC serves it: each generated entry point is one call
// of rpc::Serve (common/rpc/handler.h) with the handler of ResampleService, so
// the service itself knows nothing of gRPC and its handlers are tested as
// functions.
#ifndef MESHSEEK_SERVICES_RESAMPLE_RESAMPLE_GRPC_H_
#define MESHSEEK_SERVICES_RESAMPLE_RESAMPLE_GRPC_H_

#include "common/rpc/handler.h"
#include "meshseek/v1/resample.grpc.pb.h"
#include "services/resample/resample_service.h"

namespace meshseek {

class ResampleGrpc final : public v1::Resample::Service {
 public:
  /// `service` is not owned and outlives this.
  explicit ResampleGrpc(ResampleService* service) : service_(service) {}

  grpc::Status Resample(grpc::ServerContext* context,
                        const v1::ResampleRequest* request,
                        v1::ResampleResponse* response) override {
    return rpc::Serve(context, request, response, service_, &ResampleService::Resample);
  }

 private:
  ResampleService* const service_;
};

}  // namespace meshseek

#endif  // MESHSEEK_SERVICES_RESAMPLE_RESAMPLE_GRPC_H_
