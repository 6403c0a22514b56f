#include "transport/frame_socket.h"

#include "core/interrupt.h"

#include <poll.h>
#include <sys/socket.h>
#include <sys/uio.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace convoy::transport {

FrameSocket::~FrameSocket() { close(); }

void FrameSocket::close() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

bool FrameSocket::send(const std::string& payload) {
  if (fd_ < 0) return false;
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

bool FrameSocket::read_exact(char* dst, size_t n, Deadline deadline, RecvStatus* status) {
  size_t got = 0;
  while (got < n) {
    ssize_t r = ::recv(fd_, dst + got, n - got, MSG_DONTWAIT);
    if (r > 0) {
      got += static_cast<size_t>(r);
      continue;
    }
    if (r == 0) {
      *status = RecvStatus::kClosed;
      return false;
    }
    if (errno == EINTR) continue;
    if (errno != EAGAIN && errno != EWOULDBLOCK) {
      *status = RecvStatus::kClosed;
      return false;
    }
    if (interrupted()) {
      *status = RecvStatus::kInterrupted;
      return false;
    }
    int timeout_ms = 100;  // wake now and then to notice an interrupt
    if (deadline != Deadline::max()) {
      auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - SteadyClock::now());
      if (left.count() <= 0) {
        *status = RecvStatus::kTimeout;
        return false;
      }
      timeout_ms = static_cast<int>(std::min<int64_t>(left.count() + 1, 100));
    }
    pollfd p{fd_, POLLIN, 0};
    int pr = ::poll(&p, 1, timeout_ms);
    if (pr < 0 && errno != EINTR) {
      *status = RecvStatus::kClosed;
      return false;
    }
  }
  return true;
}

RecvStatus FrameSocket::recv(std::string* payload, Deadline deadline) {
  if (fd_ < 0) return RecvStatus::kClosed;
  RecvStatus status = RecvStatus::kOk;
  unsigned char header[4];
  if (!read_exact(reinterpret_cast<char*>(header), 4, deadline, &status)) return status;
  uint32_t len = header[0] | (header[1] << 8) | (header[2] << 16) |
                 (static_cast<uint32_t>(header[3]) << 24);
  payload->resize(len);
  if (len > 0 && !read_exact(payload->data(), len, deadline, &status)) return status;
  return RecvStatus::kOk;
}

void make_socket_pair(int fds[2]) {
  if (::socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, fds) != 0)
    throw std::runtime_error(std::string("socketpair: ") + std::strerror(errno));
}

}  // namespace convoy::transport
