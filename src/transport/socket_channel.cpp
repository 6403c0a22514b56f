#include <cstdlib>

#include "transport/engine_channel.h"
#include "transport/frame_socket.h"

namespace convoy::transport {
namespace {

class SocketChannel final : public EngineChannel {
 public:
  explicit SocketChannel(int fd) : socket_(fd) {
    const char* spin = std::getenv("CONVOY_SPIN_US");
    socket_.set_spin(spin ? std::atoll(spin) * 1000 : 100'000, true);
  }

  void start(const engine::Request& request, Deadline deadline) override {
    deadline_ = deadline;
    out_.clear();
    request.SerializeToString(&out_);
    send_failed_ = !socket_.send(out_);
  }

  CallStatus finish(engine::Reply* reply, Deadline limit) override {
    if (send_failed_) return CallStatus::kClosed;
    switch (socket_.recv(&in_, std::min(deadline_, limit))) {
      case RecvStatus::kClosed:
        return CallStatus::kClosed;
      case RecvStatus::kTimeout:
        return CallStatus::kTimeout;
      case RecvStatus::kInterrupted:
        return CallStatus::kInterrupted;
      case RecvStatus::kOk:
        break;
    }
    if (!reply->ParseFromString(in_)) return CallStatus::kClosed;
    return CallStatus::kOk;
  }

  void close() override { socket_.close(); }
  std::string describe() const override { return "socket fd " + std::to_string(socket_.fd()); }

 private:
  FrameSocket socket_;
  Deadline deadline_{};
  std::string out_, in_;
  bool send_failed_ = false;
};

}  // namespace

std::unique_ptr<EngineChannel> make_socket_channel(int fd) {
  return std::make_unique<SocketChannel>(fd);
}

}  // namespace convoy::transport
