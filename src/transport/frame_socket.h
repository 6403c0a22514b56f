// Length-prefixed frames on a stream socket: the local engine transport.
//
// A frame is a 4-byte little-endian length followed by that many bytes. Reads honour a
// deadline and report a closed peer distinctly, so a crashed engine is noticed at once.
#pragma once

#include <string>

#include "core/clock.h"

namespace convoy::transport {

enum class RecvStatus { kOk, kClosed, kTimeout, kInterrupted };

class FrameSocket {
 public:
  explicit FrameSocket(int fd) : fd_(fd) {}
  ~FrameSocket();
  FrameSocket(const FrameSocket&) = delete;
  FrameSocket& operator=(const FrameSocket&) = delete;

  int fd() const { return fd_; }

  // Sends one frame. Returns false if the peer has gone.
  bool send(const std::string& payload);
  // Receives one frame into `payload`.
  RecvStatus recv(std::string* payload, Deadline deadline);
  void close();

 private:
  bool read_exact(char* dst, size_t n, Deadline deadline, RecvStatus* status);
  int fd_;
};

// Creates a connected pair of stream sockets (close-on-exec on both).
void make_socket_pair(int fds[2]);

}  // namespace convoy::transport
