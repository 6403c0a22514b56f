#include "transport/frame_socket.h"

#include <poll.h>
#include <sched.h>
#include <sys/socket.h>
#include <sys/uio.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

#include "core/interrupt.h"

namespace convoy::transport {

FrameSocket::FrameSocket(int fd) : fd_(fd) {}

FrameSocket::~FrameSocket() { close(); }

void FrameSocket::close() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

bool FrameSocket::send(const std::string& payload) {
  if (fd_ < 0 || payload.size() > kMaxMessageBytes) return false;
  uint32_t len = static_cast<uint32_t>(payload.size());
  unsigned char header[4] = {static_cast<unsigned char>(len), static_cast<unsigned char>(len >> 8),
                             static_cast<unsigned char>(len >> 16),
                             static_cast<unsigned char>(len >> 24)};
  iovec iov[2] = {{header, 4}, {const_cast<char*>(payload.data()), payload.size()}};
  int iovcnt = 2;
  iovec* cur = iov;
  while (iovcnt > 0) {
    msghdr msg{};
    msg.msg_iov = cur;
    msg.msg_iovlen = iovcnt;
    ssize_t n = ::sendmsg(fd_, &msg, MSG_NOSIGNAL);
    if (n < 0) {
      if (errno == EINTR) continue;
      return false;
    }
    while (iovcnt > 0 && static_cast<size_t>(n) >= cur->iov_len) {
      n -= static_cast<ssize_t>(cur->iov_len);
      ++cur;
      --iovcnt;
    }
    if (iovcnt > 0) {
      cur->iov_base = static_cast<char*>(cur->iov_base) + n;
      cur->iov_len -= static_cast<size_t>(n);
    }
  }
  return true;
}

size_t FrameSocket::read_some(char* dst, size_t n, Deadline deadline, RecvStatus* status) {
  const bool planned = plan_.spin_until || plan_.sleep_until || plan_.spin2_until;
  int64_t spin_until = planned ? plan_.spin_until : spin_ns_ > 0 ? now_ns() + spin_ns_ : 0;
  for (;;) {
    ssize_t r = ::recv(fd_, dst, n, MSG_DONTWAIT);
    if (r > 0) return static_cast<size_t>(r);
    if (r < 0 && errno == EAGAIN) {
      const int64_t now = spin_until || planned ? now_ns() : 0;
      if (spin_until && now < spin_until) {
        if (spin_yield_ || planned)
          sched_yield();
        else
          __builtin_ia32_pause();
        continue;
      }
      if (planned && now < plan_.sleep_until) {
        const int64_t ns = plan_.sleep_until - now;
        timespec ts{static_cast<time_t>(ns / 1'000'000'000), static_cast<long>(ns % 1'000'000'000)};
        pollfd p{fd_, POLLIN, 0};
        ::ppoll(&p, 1, &ts, nullptr);
        continue;
      }
      if (planned && now < plan_.spin2_until) {
        spin_until = plan_.spin2_until;
        continue;
      }
    }
    if (r == 0) {
      *status = RecvStatus::kClosed;
      return 0;
    }
    if (errno != EINTR && errno != EAGAIN && errno != EWOULDBLOCK) {
      *status = RecvStatus::kClosed;
      return 0;
    }
    if (interrupted()) {
      *status = RecvStatus::kInterrupted;
      return 0;
    }
    int timeout_ms = 100;  // wake now and then to notice an interrupt
    if (deadline != Deadline::max()) {
      auto left =
          std::chrono::duration_cast<std::chrono::milliseconds>(deadline - SteadyClock::now());
      if (left.count() <= 0) {
        *status = RecvStatus::kTimeout;
        return 0;
      }
      timeout_ms = static_cast<int>(std::min<int64_t>(left.count() + 1, 100));
    }
    pollfd p{fd_, POLLIN, 0};
    ::poll(&p, 1, timeout_ms);
  }
}

RecvStatus FrameSocket::recv(std::string* payload, Deadline deadline) {
  if (fd_ < 0) return RecvStatus::kClosed;
  struct ClearPlan {  // plan_wait() holds for one recv
    WaitPlan& plan;
    ~ClearPlan() { plan = {}; }
  } clear_plan{plan_};
  RecvStatus status = RecvStatus::kOk;
  constexpr size_t kChunk = 1 << 16;
  for (;;) {
    size_t avail = buffer_len_ - buffer_pos_;
    if (avail >= 4) {
      const auto* h = reinterpret_cast<const unsigned char*>(buffer_.data() + buffer_pos_);
      size_t len = h[0] | (h[1] << 8) | (h[2] << 16) | (static_cast<size_t>(h[3]) << 24);
      if (len > kMaxMessageBytes) return RecvStatus::kClosed;  // the stream cannot be trusted
      if (avail >= 4 + len) {
        payload->assign(buffer_.data() + buffer_pos_ + 4, len);
        buffer_pos_ += 4 + len;
        if (buffer_pos_ == buffer_len_) buffer_pos_ = buffer_len_ = 0;
        return RecvStatus::kOk;
      }
      if (len > kChunk) {
        // A large frame: read the rest straight into the payload.
        payload->resize(len);
        size_t have = avail - 4;
        std::memcpy(payload->data(), buffer_.data() + buffer_pos_ + 4, have);
        buffer_pos_ = buffer_len_ = 0;
        while (have < len) {
          size_t r = read_some(payload->data() + have, len - have, deadline, &status);
          if (r == 0) return status;
          have += r;
        }
        return RecvStatus::kOk;
      }
    }
    if (buffer_pos_ > 0) {
      std::memmove(buffer_.data(), buffer_.data() + buffer_pos_, avail);
      buffer_pos_ = 0;
      buffer_len_ = avail;
    }
    if (buffer_.size() < buffer_len_ + kChunk) buffer_.resize(buffer_len_ + kChunk);
    size_t r =
        read_some(buffer_.data() + buffer_len_, buffer_.size() - buffer_len_, deadline, &status);
    if (r == 0) return status;
    buffer_len_ += r;
  }
}

void make_socket_pair(int fds[2]) {
  if (::socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, fds) != 0)
    throw std::runtime_error(std::string("socketpair: ") + std::strerror(errno));
  // Large inline frames (no shared memory) pass in fewer wake-ups with larger buffers; the
  // kernel caps these at net.core.wmem_max unless we may force them.
  int bytes = 8 << 20;
  for (int i = 0; i < 2; ++i) {
    if (setsockopt(fds[i], SOL_SOCKET, SO_SNDBUFFORCE, &bytes, sizeof bytes) != 0)
      setsockopt(fds[i], SOL_SOCKET, SO_SNDBUF, &bytes, sizeof bytes);
  }
}

}  // namespace convoy::transport
