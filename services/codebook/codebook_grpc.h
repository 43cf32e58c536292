// The codebook service as gRPC serves it: each generated entry point is one call
// of rpc::Serve (common/rpc/handler.h) with the handler of CodebookService, so
// the service itself knows nothing of gRPC and its handlers are tested as
// functions.
#ifndef MESHSEEK_SERVICES_CODEBOOK_CODEBOOK_GRPC_H_
#define MESHSEEK_SERVICES_CODEBOOK_CODEBOOK_GRPC_H_

#include "common/rpc/handler.h"
#include "meshseek/v1/codebook.grpc.pb.h"
#include "services/codebook/codebook_service.h"

namespace meshseek {

class CodebookGrpc final : public v1::Codebook::Service {
 public:
  /// `service` is not owned and outlives this.
  explicit CodebookGrpc(CodebookService* service) : service_(service) {}

  grpc::Status Train(grpc::ServerContext* context,
                     grpc::ServerReader<v1::TrainCodebookRequest>* reader,
                     v1::CodebookInfo* response) override {
    return rpc::Serve(context, reader, response, service_, &CodebookService::Train);
  }
  grpc::Status Encode(grpc::ServerContext* context,
                      const v1::EncodeRequest* request,
                      v1::EncodeResponse* response) override {
    return rpc::Serve(context, request, response, service_, &CodebookService::Encode);
  }
  grpc::Status GetCodebook(grpc::ServerContext* context,
                           const v1::GetCodebookRequest* request,
                           v1::CodebookInfo* response) override {
    return rpc::Serve(context, request, response, service_, &CodebookService::GetCodebook);
  }

 private:
  CodebookService* const service_;
};

}  // namespace meshseek

#endif  // MESHSEEK_SERVICES_CODEBOOK_CODEBOOK_GRPC_H_
