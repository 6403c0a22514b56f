// Length-prefixed frames on a stream socket: the local engine transport.
//
// A frame is a 4-byte little-endian length followed by that many bytes. Reads honour a
// deadline and report a closed peer distinctly, so a crashed engine is noticed at once.
// A frame carries one message of at most kMaxMessageBytes: larger ones are not sent, and a
// header announcing one ends the stream (its peer is broken or hostile).
#pragma once

#include <cstddef>
#include <string>

#include "core/clock.h"

namespace convoy::transport {

// The largest message (a request or reply, with its inline datapacks) between the
// coordinator and an engine: 1 GiB, half of protobuf's 2 GiB limit. Large payloads belong in
// shared-memory blobs (transport/blobs.h), which a message only points to.
constexpr size_t kMaxMessageBytes = size_t{1} << 30;

enum class RecvStatus { kOk, kClosed, kTimeout, kInterrupted };

class FrameSocket {
 public:
  explicit FrameSocket(int fd);
  ~FrameSocket();
  FrameSocket(const FrameSocket&) = delete;
  FrameSocket& operator=(const FrameSocket&) = delete;

  int fd() const { return fd_; }

  // Sends one frame. Returns false if the peer has gone or `payload` is larger than
  // kMaxMessageBytes (then nothing is sent).
  bool send(const std::string& payload);
  // Receives one frame into `payload`; kClosed for a frame larger than kMaxMessageBytes.
  RecvStatus recv(std::string* payload, Deadline deadline);
  void close();
  // Polls up to `ns` for data before sleeping, pausing or (yield) giving up the CPU between
  // polls: a reply that comes within that time is seen without a scheduler wake-up, which
  // costs tens of microseconds on some VMs.
  void set_spin(int64_t ns, bool yield = false) {
    spin_ns_ = ns;
    spin_yield_ = yield;
  }
  // For the next recv only, a wait in three phases before blocking (steady-clock ns; a phase
  // already over is skipped): yield the CPU until `spin_until`, then sleep (woken at once by
  // data) until `sleep_until`, then yield again until `spin2_until`. For a caller that knows
  // when a long reply is due: it spins for a short reply, leaves the core to others while a
  // long one is computed, and spins again shortly before it is due.
  void plan_wait(int64_t spin_until, int64_t sleep_until, int64_t spin2_until) {
    plan_ = {spin_until, sleep_until, spin2_until};
  }

 private:
  // One blocking read into `dst` (at most `n` bytes); 0 with `status` set when none.
  size_t read_some(char* dst, size_t n, Deadline deadline, RecvStatus* status);
  int fd_;
  int64_t spin_ns_ = 0;
  bool spin_yield_ = false;
  struct WaitPlan {
    int64_t spin_until = 0, sleep_until = 0, spin2_until = 0;
  } plan_;
  std::string buffer_;  // bytes received but not yet returned, from buffer_pos_
  size_t buffer_pos_ = 0, buffer_len_ = 0;
};

// Creates a connected pair of stream sockets (close-on-exec on both).
void make_socket_pair(int fds[2]);

}  // namespace convoy::transport
