// The one RPC edge of every service. A handler is written over the core in
// absl terms:
//
//   unary          absl::StatusOr<Response> Method(const Request&, const CallContext&)
//   server stream  absl::Status Method(const Request&, Writer<Response>, const CallContext&)
//   client stream  absl::StatusOr<Response> Method(Reader<Request>, const CallContext&)
//   bidirectional  absl::Status Method(Reader<Request>, Writer<Response>, const CallContext&)
//
// The service class knows nothing of gRPC: its binding (services/NAME/NAME_grpc.h,
// deriving from the generated v1::NAME::Service) overrides each generated entry
// point with one call of Serve below and the handler's address. Serve turns the
// handler's absl::Status into the grpc::Status with the same canonical code and
// message (status.h), fills the response, and gives the handler the call's
// deadline and cancellation. What
// every call also gets (counting and timing by method and code, admission,
// message limits) is the server's (server.h), so no handler repeats it.
#ifndef MESHSEEK_COMMON_RPC_HANDLER_H_
#define MESHSEEK_COMMON_RPC_HANDLER_H_

#include <grpcpp/server_context.h>
#include <grpcpp/support/sync_stream.h>

#include <utility>

#include "absl/functional/function_ref.h"
#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/time/time.h"
#include "common/rpc/status.h"

namespace meshseek::rpc {

/// What a handler may know of its call.
class CallContext {
 public:
  /// nullptr: a call from inside the process, no deadline, never cancelled.
  explicit CallContext(grpc::ServerContext* context) : context_(context) {}
  /// absl::InfiniteFuture() when the client set none.
  absl::Time deadline() const {
    return context_ == nullptr ? absl::InfiniteFuture() : absl::FromChrono(context_->deadline());
  }
  /// The client went away, or the deadline passed.
  bool cancelled() const { return context_ != nullptr && context_->IsCancelled(); }

 private:
  grpc::ServerContext* context_;
};

/// The next message of a client stream into *message; false at its end.
template <typename Message>
using Reader = absl::FunctionRef<bool(Message*)>;
/// Sends one message of a server stream; false when the stream is closed.
template <typename Message>
using Writer = absl::FunctionRef<bool(const Message&)>;

/// Unary.
template <typename Self, typename Request, typename Response>
grpc::Status Serve(grpc::ServerContext* context,
                   const Request* request,
                   Response* response,
                   Self* self,
                   absl::StatusOr<Response> (Self::*handler)(const Request&, const CallContext&)) {
  absl::StatusOr<Response> result = (self->*handler)(*request, CallContext(context));
  if (!result.ok()) return ToGrpcStatus(result.status());
  *response = *std::move(result);
  return grpc::Status::OK;
}

/// Server stream.
template <typename Self, typename Request, typename Response>
grpc::Status Serve(
    grpc::ServerContext* context,
    const Request* request,
    grpc::ServerWriter<Response>* writer,
    Self* self,
    absl::Status (Self::*handler)(const Request&, Writer<Response>, const CallContext&)) {
  auto write = [writer](const Response& message) { return writer->Write(message); };
  return ToGrpcStatus((self->*handler)(*request, write, CallContext(context)));
}

/// Client stream.
template <typename Self, typename Request, typename Response>
grpc::Status Serve(grpc::ServerContext* context,
                   grpc::ServerReader<Request>* reader,
                   Response* response,
                   Self* self,
                   absl::StatusOr<Response> (Self::*handler)(Reader<Request>, const CallContext&)) {
  auto read = [reader](Request* message) { return reader->Read(message); };
  absl::StatusOr<Response> result = (self->*handler)(read, CallContext(context));
  if (!result.ok()) return ToGrpcStatus(result.status());
  *response = *std::move(result);
  return grpc::Status::OK;
}

/// Bidirectional stream.
template <typename Self, typename Request, typename Response>
grpc::Status Serve(
    grpc::ServerContext* context,
    grpc::ServerReaderWriter<Response, Request>* stream,
    Self* self,
    absl::Status (Self::*handler)(Reader<Request>, Writer<Response>, const CallContext&)) {
  auto read = [stream](Request* message) { return stream->Read(message); };
  auto write = [stream](const Response& message) { return stream->Write(message); };
  return ToGrpcStatus((self->*handler)(read, write, CallContext(context)));
}

}  // namespace meshseek::rpc

#endif  // MESHSEEK_COMMON_RPC_HANDLER_H_
