// A local call channel: request/reply calls as frames (frame_socket.h) on a Unix socket, for a
// client on the same machine that wants a call to cost microseconds rather than gRPC's tens of
// them. NRPCoreSim's server mode offers its calls here too (`--local_socket PATH`, used by
// python/nrp_client's `NrpCore(..., local_channel=True)`); the gRPC service stays the contract.
//
// A request frame is one byte naming the method, then the request's bytes; the reply frame is
// one byte of status (a gRPC status code: 0 is OK), then the reply's bytes (OK) or the error
// message (UTF-8). Calls on one connection are answered in order, one at a time; connections
// are served one after the other.
//
//   LocalRpcServer server("/tmp/x/sim.sock", [](uint8_t method, const std::string& request) {
//     return LocalReply{0, answer(method, request)};
//   });
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <string>
#include <thread>

namespace convoy::transport {

struct LocalReply {
  int status = 0;       // a gRPC status code; 0: OK
  std::string payload;  // the reply (OK) or the error message
};

class LocalRpcServer {
 public:
  using Handler = std::function<LocalReply(uint8_t method, const std::string& request)>;
  // Runs the serving thread's body (what a caller wants around it for the thread's life: an
  // embedded interpreter's thread state, say).
  using ThreadWrapper = std::function<void(const std::function<void()>& body)>;

  // Listens at `path` (a Unix socket, made there; a stale socket file is replaced; the file is
  // the caller's to protect: put it in a private folder) and serves calls from a thread of its
  // own. Throws std::runtime_error naming the path when it cannot listen.
  LocalRpcServer(const std::string& path, Handler handler, ThreadWrapper wrapper = {});
  // Stops serving (a call in progress finishes first) and removes the socket file.
  ~LocalRpcServer();
  LocalRpcServer(const LocalRpcServer&) = delete;
  LocalRpcServer& operator=(const LocalRpcServer&) = delete;

  const std::string& path() const { return path_; }

 private:
  void serve();
  void serve_connection(int fd);

  std::string path_;
  Handler handler_;
  int listen_fd_ = -1;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace convoy::transport
