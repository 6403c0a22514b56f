// Serves one Engine over the engine protocol: on an inherited socket (local engines) or as
// a gRPC server (remote engines). Exceptions thrown by the engine become error replies.
#pragma once

#include <string>

#include "engine/engine.h"
#include "transport/blobs.h"
#include "transport/grpc_security.h"

namespace convoy::engines {

class EngineServer {
 public:
  explicit EngineServer(Engine& engine) : engine_(engine) {}

  // Handles one request. Returns false once the engine has been shut down.
  bool handle(const engine::Request& request, engine::Reply* reply);

  // Waiting for the next request, yield the CPU in a loop before sleeping (cheaper than a
  // wake-up) when the coordinator usually comes back within `us`: for a little longer than
  // its usual gap, at most `us`, or at most 50 µs if the engine usually works less than it
  // waits (it is not the one the loop waits for). An engine that usually waits longer sleeps
  // at once.
  void set_spin_us(int64_t us) { spin_us_ = us; }

  // Serves requests on a connected stream socket until Shutdown or until the peer closes.
  // Blobs of replies go into the arena `shm_out_fd`, those of requests come from `shm_in_fd`
  // (-1: inline).
  void serve_socket(int fd, int shm_out_fd = -1, int shm_in_fd = -1);
  // Serves gRPC at `address` until Shutdown, with TLS and a token as `security` says (see
  // transport/grpc_security.h; throws std::invalid_argument when the address is not the
  // loopback and there is neither, unless security.insecure).
  void serve_grpc(const std::string& address, const transport::ServerSecurity& security);

 private:
  void do_step(const engine::StepRequest& request, engine::StepReply* reply);
  Engine& engine_;
  bool initialized_ = false;
  bool shut_down_ = false;
  int64_t spin_us_ = 0;
  void get(const engine::DataPackId& id, engine::DataPack* out);
  void put(const engine::DataPack& dp);
  const transport::ShmBlobWriter* shm_writer_ = nullptr;  // serve_socket's, if any
  // The blobs of requests are read with blob_reader_, those of replies written with
  // blob_writer_: inline unless serve_socket has shared-memory arenas.
  datapack::InlineBlobWriter inline_writer_;
  datapack::BlobWriter* blob_writer_ = &inline_writer_;
  const datapack::BlobReader* blob_reader_ = &datapack::inline_blob_reader();
  std::vector<const engine::DataPackId*> stale_;  // do_step's, reused
};

// main() of every convoy-engine-<type> binary.
int engine_main(int argc, char** argv);

}  // namespace convoy::engines
