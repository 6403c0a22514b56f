#include <grpcpp/grpcpp.h>

#include <future>

#include "convoy/engine.grpc.pb.h"
#include "core/interrupt.h"
#include "transport/engine_channel.h"
#include "transport/frame_socket.h"

namespace convoy::transport {
namespace {

class GrpcChannel final : public EngineChannel {
 public:
  GrpcChannel(std::string address, std::shared_ptr<grpc::Channel> channel)
      : address_(std::move(address)), stub_(engine::Engine::NewStub(channel)) {}

  ~GrpcChannel() override {
    if (context_) context_->TryCancel();
    if (pending_.valid()) pending_.wait();
  }

  void start(const engine::Request& request, Deadline deadline) override {
    context_ = std::make_unique<grpc::ClientContext>();
    if (deadline != Deadline::max()) {
      context_->set_deadline(std::chrono::system_clock::now() + (deadline - SteadyClock::now()));
    }
    deadline_ = deadline;
    pending_ = std::async(std::launch::async, [this, request] { return call(request); });
  }

  CallStatus finish(engine::Reply* reply, Deadline limit) override {
    Deadline deadline = std::min(deadline_, limit);
    for (;;) {
      auto slice = SteadyClock::now() + std::chrono::milliseconds(100);
      if (pending_.wait_until(std::min(slice, deadline)) == std::future_status::ready) break;
      if (interrupted() || SteadyClock::now() >= deadline) {
        context_->TryCancel();
        pending_.wait();
        pending_.get();
        return interrupted() ? CallStatus::kInterrupted : CallStatus::kTimeout;
      }
    }
    auto [status, result] = pending_.get();
    if (status.error_code() == grpc::StatusCode::DEADLINE_EXCEEDED) return CallStatus::kTimeout;
    if (status.error_code() == grpc::StatusCode::UNAVAILABLE ||
        status.error_code() == grpc::StatusCode::CANCELLED)
      return CallStatus::kClosed;
    *reply = std::move(result);
    if (!status.ok()) reply->set_error(status.error_message());
    return CallStatus::kOk;
  }

  void close() override {}
  std::string describe() const override { return "grpc " + address_; }

 private:
  std::pair<grpc::Status, engine::Reply> call(const engine::Request& request) {
    engine::Reply reply;
    grpc::Status status;
    auto* ctx = context_.get();
    switch (request.kind_case()) {
      case engine::Request::kInitialize:
        status = stub_->Initialize(ctx, request.initialize(), reply.mutable_initialize());
        break;
      case engine::Request::kStep:
        status = stub_->Step(ctx, request.step(), reply.mutable_step());
        break;
      case engine::Request::kGetDatapacks:
        status = stub_->GetDataPacks(ctx, request.get_datapacks(), reply.mutable_get_datapacks());
        break;
      case engine::Request::kSetDatapacks:
        status = stub_->SetDataPacks(ctx, request.set_datapacks(), reply.mutable_done());
        break;
      case engine::Request::kReset:
        status = stub_->Reset(ctx, request.reset(), reply.mutable_done());
        break;
      case engine::Request::kShutdown:
        status = stub_->Shutdown(ctx, request.shutdown(), reply.mutable_done());
        break;
      default:
        status = grpc::Status(grpc::StatusCode::INVALID_ARGUMENT, "empty request");
    }
    return {status, std::move(reply)};
  }

  std::string address_;
  std::unique_ptr<engine::Engine::Stub> stub_;
  std::unique_ptr<grpc::ClientContext> context_;
  std::future<std::pair<grpc::Status, engine::Reply>> pending_;
  Deadline deadline_{};
};

}  // namespace

std::unique_ptr<EngineChannel> make_grpc_channel(const std::string& address, Deadline deadline) {
  grpc::ChannelArguments args;
  args.SetMaxReceiveMessageSize(static_cast<int>(kMaxMessageBytes));
  args.SetMaxSendMessageSize(static_cast<int>(kMaxMessageBytes));
  auto channel = grpc::CreateCustomChannel(address, grpc::InsecureChannelCredentials(), args);
  auto wait_until =
      deadline == Deadline::max() ? SteadyClock::now() + std::chrono::seconds(60) : deadline;
  if (!channel->WaitForConnected(std::chrono::system_clock::now() +
                                 (wait_until - SteadyClock::now()))) {
    return nullptr;
  }
  return std::make_unique<GrpcChannel>(address, std::move(channel));
}

}  // namespace convoy::transport
