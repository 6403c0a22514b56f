#include "transport/local_rpc.h"

#include <poll.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <stdexcept>

#include "transport/frame_socket.h"

namespace convoy::transport {

namespace {

constexpr int kPollMs = 100;  // how soon a stop is noticed
constexpr int64_t kMaxSpinNs = 300'000;

int64_t now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

int listen_at(const std::string& path) {
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  if (path.empty() || path.size() >= sizeof addr.sun_path)
    throw std::runtime_error("local socket '" + path + "': the path must have 1 to " +
                             std::to_string(sizeof addr.sun_path - 1) + " characters");
  std::memcpy(addr.sun_path, path.c_str(), path.size() + 1);
  const int fd = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd < 0) throw std::runtime_error("local socket '" + path + "': " + std::strerror(errno));
  ::unlink(path.c_str());  // a socket file left by a process that is gone
  if (::bind(fd, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0 ||
      ::listen(fd, 4) != 0) {
    const std::string why = std::strerror(errno);
    ::close(fd);
    throw std::runtime_error("local socket '" + path + "': cannot listen there: " + why);
  }
  return fd;
}

}  // namespace

LocalRpcServer::LocalRpcServer(const std::string& path, Handler handler, ThreadWrapper wrapper)
    : path_(path), handler_(std::move(handler)), listen_fd_(listen_at(path)) {
  thread_ = std::thread([this, wrapper = std::move(wrapper)] {
    if (wrapper)
      wrapper([this] { serve(); });
    else
      serve();
  });
}

LocalRpcServer::~LocalRpcServer() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
  ::close(listen_fd_);
  ::unlink(path_.c_str());
}

void LocalRpcServer::serve() {
  while (!stop_) {
    pollfd p{listen_fd_, POLLIN, 0};
    if (::poll(&p, 1, kPollMs) <= 0) continue;
    const int fd = ::accept4(listen_fd_, nullptr, nullptr, SOCK_CLOEXEC);
    if (fd >= 0) serve_connection(fd);
  }
}

void LocalRpcServer::serve_connection(int fd) {
  FrameSocket conn(fd);  // closes fd
  std::string request;
  // A client that calls again within kMaxSpinNs of a reply (a learning agent stepping) is
  // waited for by yielding the CPU rather than sleeping: no scheduler wake-up per call.
  int64_t usual_gap_ns = -1;
  const char* fixed = std::getenv("CONVOY_SPIN_US");  // as the engines' channels: 0 never spins
  const int64_t fixed_spin_ns = fixed ? std::max<int64_t>(0, std::atoll(fixed)) * 1000 : -1;
  while (!stop_) {
    if (fixed_spin_ns >= 0)
      conn.set_spin(fixed_spin_ns, true);
    else if (usual_gap_ns >= 0 && usual_gap_ns <= kMaxSpinNs)
      conn.set_spin(std::min(kMaxSpinNs, usual_gap_ns + usual_gap_ns / 4 + 20'000), true);
    else
      conn.set_spin(0);
    const int64_t waited_from = now_ns();
    const RecvStatus got = conn.recv(&request, deadline_after(kPollMs / 1000.0));
    if (got == RecvStatus::kTimeout || got == RecvStatus::kInterrupted) {
      usual_gap_ns = -1;
      continue;
    }
    if (got != RecvStatus::kOk) return;  // the client has gone
    const int64_t gap = now_ns() - waited_from;
    usual_gap_ns = usual_gap_ns < 0 ? gap : (3 * usual_gap_ns + gap) / 4;
    LocalReply reply;
    if (request.empty()) {
      reply = {3, "an empty request (no method byte)"};  // INVALID_ARGUMENT
    } else {
      const auto method = static_cast<uint8_t>(request[0]);
      request.erase(0, 1);
      try {
        reply = handler_(method, request);
      } catch (const std::exception& e) {
        reply = {13, e.what()};  // INTERNAL
      }
    }
    std::string frame(1, static_cast<char>(reply.status));
    frame += reply.payload;
    if (!conn.send(frame)) return;
  }
}

}  // namespace convoy::transport
