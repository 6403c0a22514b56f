#include <algorithm>
#include <chrono>
#include <cstdlib>

#include "transport/engine_channel.h"
#include "transport/frame_socket.h"

namespace convoy::transport {
namespace {

class SocketChannel final : public EngineChannel {
 public:
  explicit SocketChannel(int fd) : socket_(fd) {
    if (const char* spin = std::getenv("CONVOY_SPIN_US")) fixed_spin_ns_ = std::atoll(spin) * 1000;
    socket_.set_spin(fixed_spin_ns_ >= 0 ? fixed_spin_ns_ : kMinSpinNs, true);
  }

  void start(const engine::Request& request, Deadline deadline) override {
    started_ns_ = now_ns();
    deadline_ = deadline;
    out_.clear();
    request.SerializeToString(&out_);
    send_failed_ = !socket_.send(out_);
  }

  CallStatus finish(engine::Reply* reply, Deadline limit) override {
    if (send_failed_) return CallStatus::kClosed;
    if (fixed_spin_ns_ < 0) {
      // Wait for the reply by yielding the CPU (not sleeping: waking up costs tens of
      // microseconds here) until a little past the engine's usual round trip, up to 2 ms.
      int64_t until = started_ns_ + std::min<int64_t>(kMaxSpinNs, usual_ns_ + usual_ns_ / 4);
      socket_.set_spin(std::max<int64_t>(kMinSpinNs, until - now_ns()), true);
    }
    RecvStatus status = socket_.recv(&in_, std::min(deadline_, limit));
    if (status == RecvStatus::kOk) {
      // The usual round trip: a running average that follows changes within a few calls.
      int64_t took = now_ns() - started_ns_;
      usual_ns_ = usual_ns_ == 0 ? took : (3 * usual_ns_ + took) / 4;
    }
    switch (status) {
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
  static int64_t now_ns() {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(
               std::chrono::steady_clock::now().time_since_epoch())
        .count();
  }
  static constexpr int64_t kMinSpinNs = 100'000, kMaxSpinNs = 2'000'000;

  FrameSocket socket_;
  int64_t fixed_spin_ns_ = -1;  // CONVOY_SPIN_US, when set
  int64_t started_ns_ = 0, usual_ns_ = 0;
  Deadline deadline_{};
  std::string out_, in_;
  bool send_failed_ = false;
};

}  // namespace

std::unique_ptr<EngineChannel> make_socket_channel(int fd) {
  return std::make_unique<SocketChannel>(fd);
}

}  // namespace convoy::transport
