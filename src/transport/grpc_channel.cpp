#include <grpcpp/grpcpp.h>
#include <netdb.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <future>

#include "convoy/engine.grpc.pb.h"
#include "core/interrupt.h"
#include "transport/engine_channel.h"
#include "transport/frame_socket.h"
#include "transport/grpc_security.h"

namespace convoy::transport {
namespace {

class GrpcChannel final : public EngineChannel {
 public:
  GrpcChannel(std::string address, std::shared_ptr<grpc::Channel> channel, std::string token)
      : address_(std::move(address)),
        stub_(engine::Engine::NewStub(channel)),
        token_(std::move(token)) {}

  ~GrpcChannel() override {
    if (context_) context_->TryCancel();
    if (pending_.valid()) pending_.wait();
  }

  void start(const engine::Request& request, Deadline deadline) override {
    context_ = std::make_unique<grpc::ClientContext>();
    if (!token_.empty()) context_->AddMetadata(kTokenMetadataKey, token_);
    if (deadline != Deadline::max()) {
      context_->set_deadline(std::chrono::system_clock::now() + (deadline - SteadyClock::now()));
    }
    deadline_ = deadline;
    pending_ = std::async(std::launch::async, [this, request] { return call(request); });
  }

  // The call's own gRPC deadline stays: the engine answered (or not) in its time meanwhile.
  void postpone(SteadyClock::duration delay) override {
    if (deadline_ != Deadline::max()) deadline_ += delay;
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
    if (status.error_code() == grpc::StatusCode::UNAUTHENTICATED) {
      reply->set_error("the engine server refused the coordinator at " + address_ + ": " +
                       status.error_message() + " (AuthToken, or $" + kTokenEnv + ")");
    } else if (!status.ok()) {
      reply->set_error(status.error_message());
      reply->set_user_error(status.error_code() == grpc::StatusCode::INVALID_ARGUMENT);
    }
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
  std::string token_;  // sent with every call; never logged
  std::unique_ptr<grpc::ClientContext> context_;
  std::future<std::pair<grpc::Status, engine::Reply>> pending_;
  Deadline deadline_{};
};

// Whether a TCP connection to host:port opens within half a second: something listens.
bool tcp_answers(const std::string& address) {
  if (address.rfind("unix", 0) == 0) return false;
  std::string host = address, port;
  const auto colon = host.rfind(':');
  if (colon == std::string::npos) return false;
  port = host.substr(colon + 1);
  host = host.substr(0, colon);
  if (host.size() > 1 && host.front() == '[') host = host.substr(1, host.size() - 2);
  addrinfo hints{};
  hints.ai_socktype = SOCK_STREAM;
  addrinfo* found = nullptr;
  if (getaddrinfo(host.c_str(), port.c_str(), &hints, &found) != 0) return false;
  bool open = false;
  for (addrinfo* a = found; a && !open; a = a->ai_next) {
    int fd = socket(a->ai_family, a->ai_socktype | SOCK_NONBLOCK | SOCK_CLOEXEC, a->ai_protocol);
    if (fd < 0) continue;
    if (connect(fd, a->ai_addr, a->ai_addrlen) == 0) {
      open = true;
    } else if (errno == EINPROGRESS) {
      pollfd p{fd, POLLOUT, 0};
      int err = 0;
      socklen_t len = sizeof err;
      open = poll(&p, 1, 500) == 1 && getsockopt(fd, SOL_SOCKET, SO_ERROR, &err, &len) == 0 &&
             err == 0;
    }
    ::close(fd);
  }
  freeaddrinfo(found);
  return open;
}

}  // namespace

std::unique_ptr<EngineChannel> make_grpc_channel(const std::string& address, Deadline deadline) {
  return make_grpc_channel(address, deadline, ClientSecurity{});
}

std::unique_ptr<EngineChannel> make_grpc_channel(const std::string& address, Deadline deadline,
                                                 const ClientSecurity& security) {
  grpc::ChannelArguments args;
  args.SetMaxReceiveMessageSize(static_cast<int>(kMaxMessageBytes));
  args.SetMaxSendMessageSize(static_cast<int>(kMaxMessageBytes));
  if (security.tls && !security.server_name.empty())
    args.SetSslTargetNameOverride(security.server_name);
  auto channel = grpc::CreateCustomChannel(address, channel_credentials(security), args);
  const auto wait_until =
      deadline == Deadline::max() ? SteadyClock::now() + std::chrono::seconds(60) : deadline;
  // Something that accepts TCP connections but never lets the channel become ready, for two
  // seconds, does not speak what we speak: a failed TLS handshake, or TLS against plain.
  Deadline answered_since = Deadline::max();
  for (;;) {
    const auto now = SteadyClock::now();
    if (now >= wait_until) return nullptr;
    const auto slice = std::min(wait_until, now + std::chrono::milliseconds(250));
    if (channel->WaitForConnected(std::chrono::system_clock::now() + (slice - now))) break;
    if (interrupted()) return nullptr;
    if (channel->GetState(false) != GRPC_CHANNEL_TRANSIENT_FAILURE) continue;
    if (!tcp_answers(address)) {
      answered_since = Deadline::max();
      continue;
    }
    if (answered_since == Deadline::max()) answered_since = SteadyClock::now();
    if (SteadyClock::now() - answered_since > std::chrono::seconds(2)) {
      throw std::runtime_error(
          security.tls ? "the server at " + address +
                             " answers but the TLS handshake fails (is its certificate signed "
                             "by ServerTLS/CACertificate, and for ServerName? does it want a "
                             "client certificate? does it speak TLS?)"
                       : "the server at " + address +
                             " answers but not as a plain gRPC engine server (does it require "
                             "TLS? then give ServerTLS)");
    }
  }
  return std::make_unique<GrpcChannel>(address, std::move(channel), security.token);
}

}  // namespace convoy::transport
