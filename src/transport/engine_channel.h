// The coordinator's end of a connection to one engine server.
//
// A call is split in start() and finish() so that the coordinator can have every due
// engine working at once: it starts the step on all of them, then collects the replies.
#pragma once

#include <memory>
#include <string>

#include "convoy/engine.pb.h"
#include "core/clock.h"

namespace convoy::transport {

enum class CallStatus { kOk, kClosed, kTimeout, kInterrupted };

class EngineChannel {
 public:
  virtual ~EngineChannel() = default;
  // Starts a call. At most one call is in flight per channel. Throws std::length_error, and
  // sends nothing, when the request is larger than a message may be (kMaxMessageBytes).
  virtual void start(const engine::Request& request, Deadline deadline) = 0;
  // Waits for the reply of the call in flight, until the deadline given to start() or
  // `limit`, whichever comes first.
  virtual CallStatus finish(engine::Reply* reply, Deadline limit = Deadline::max()) = 0;
  // The deadline of the call in flight (and, where it is measured, its start) moves on by
  // `delay`: the coordinator held the loop meanwhile (a paused live run).
  virtual void postpone(SteadyClock::duration delay) { (void)delay; }
  // Closes the connection; a local engine server exits when it sees this.
  virtual void close() = 0;
  // Human-readable transport, for logs ("socket fd 7", "grpc localhost:23001").
  virtual std::string describe() const = 0;
};

// Local engine on an inherited stream socket (see FrameSocket).
std::unique_ptr<EngineChannel> make_socket_channel(int fd);
struct ClientSecurity;  // transport/grpc_security.h

// Engine serving gRPC at `address` (host:port or unix:path), with TLS and a token as
// `security` says. Waits until `deadline` for it; nullptr when nothing answers. Throws
// std::runtime_error when something answers but the connection cannot be made (a failed TLS
// handshake, plain against TLS), std::invalid_argument for unreadable certificate files.
std::unique_ptr<EngineChannel> make_grpc_channel(const std::string& address, Deadline deadline);
std::unique_ptr<EngineChannel> make_grpc_channel(const std::string& address, Deadline deadline,
                                                 const ClientSecurity& security);

}  // namespace convoy::transport
