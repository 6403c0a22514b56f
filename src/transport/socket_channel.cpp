#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <stdexcept>

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
    if (!request.SerializeToString(&out_) || out_.size() > kMaxMessageBytes) {
      throw std::length_error("the request is " + std::to_string(request.ByteSizeLong()) +
                              " bytes, more than one message may carry (" +
                              std::to_string(kMaxMessageBytes) + " bytes)");
    }
    send_failed_ = !socket_.send(out_);
  }

  CallStatus finish(engine::Reply* reply, Deadline limit) override {
    if (send_failed_) return CallStatus::kClosed;
    if (fixed_spin_ns_ < 0) plan_wait();
    RecvStatus status = socket_.recv(&in_, std::min(deadline_, limit));
    if (status == RecvStatus::kOk) learn(now_ns() - started_ns_);
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

  void postpone(SteadyClock::duration delay) override {
    if (deadline_ != Deadline::max()) deadline_ += delay;
    started_ns_ += std::chrono::duration_cast<std::chrono::nanoseconds>(delay).count();
  }

  void close() override { socket_.close(); }
  std::string describe() const override { return "socket fd " + std::to_string(socket_.fd()); }

 private:
  // Round trips are often of two kinds, short and long (an engine whose camera renders every
  // other step, say): a running average of each, which follows changes within a few calls.
  void learn(int64_t took) {
    auto follow = [](int64_t& avg, int64_t x) { avg = avg == 0 ? x : (3 * avg + x) / 4; };
    if (short_ns_ == 0 || took <= 2 * short_ns_) {
      follow(short_ns_, took);
      longs_in_a_row_ = 0;
    } else {
      follow(long_ns_, took);
      // Only long ones for a while: they are the usual ones now.
      if (++longs_in_a_row_ >= 8) {
        short_ns_ = long_ns_;
        long_ns_ = 0;
        longs_in_a_row_ = 0;
      }
    }
    if (long_ns_ != 0 && long_ns_ <= 2 * short_ns_) long_ns_ = 0;  // the kinds have merged
  }

  // Waits for the reply by yielding the CPU (not sleeping: waking up costs tens of
  // microseconds here) until a little past the usual short round trip. When long ones occur
  // too, it then sleeps (woken by the reply if it comes) until shortly before the usual long
  // one, so that the engine (a renderer's threads, say) has the other core meanwhile, and
  // yields again until a little past it. Then it blocks. When even the short ones take more
  // than 2 ms, it sleeps and yields likewise around the short one.
  void plan_wait() {
    // Sleeping first (until shortly before `due`), then yielding until a little past it.
    auto sleep_then_spin = [&](int64_t due, int64_t* sleep_until, int64_t* spin_until) {
      *sleep_until = started_ns_ + due - std::max<int64_t>(kWakeEarlyNs, due / 8);
      *spin_until = std::min(started_ns_ + due + due / 4, *sleep_until + kMaxSpinNs);
    };
    int64_t spin1 = 0, sleep_until = 0, spin2 = 0;
    if (short_ns_ > kMaxSpinNs) {  // even the short ones are long
      sleep_then_spin(short_ns_, &sleep_until, &spin2);
    } else {
      spin1 = started_ns_ + std::max<int64_t>(short_ns_ + short_ns_ / 4, kMinSpinNs);
      if (long_ns_ > 0) sleep_then_spin(long_ns_, &sleep_until, &spin2);
    }
    socket_.plan_wait(spin1, sleep_until, spin2);
  }

  static int64_t now_ns() {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(
               std::chrono::steady_clock::now().time_since_epoch())
        .count();
  }
  static constexpr int64_t kMinSpinNs = 100'000, kMaxSpinNs = 2'000'000, kWakeEarlyNs = 200'000;

  FrameSocket socket_;
  int64_t fixed_spin_ns_ = -1;  // CONVOY_SPIN_US, when set
  int64_t started_ns_ = 0, short_ns_ = 0, long_ns_ = 0;
  int longs_in_a_row_ = 0;
  Deadline deadline_{};
  std::string out_, in_;
  bool send_failed_ = false;
};

}  // namespace

std::unique_ptr<EngineChannel> make_socket_channel(int fd) {
  return std::make_unique<SocketChannel>(fd);
}

}  // namespace convoy::transport
