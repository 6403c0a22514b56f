// The coordinator's view of one running engine: its channel, its process, its clock.
#pragma once

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "config/simulation_config.h"
#include "convoy/engine.pb.h"
#include "launch/process_launcher.h"
#include "transport/blobs.h"
#include "transport/engine_channel.h"

namespace convoy::loop {

class EngineHandle {
 public:
  EngineHandle(const config::EngineConfig& config, std::filesystem::path log_file)
      : config_(config), log_file_(std::move(log_file)) {}

  const std::string& name() const { return config_.name; }
  const config::EngineConfig& config() const { return config_; }
  const std::filesystem::path& log_file() const { return log_file_; }
  launch::ChildProcess& process() { return process_; }

  // Connects the handle. `process` is the engine's process if the coordinator started it;
  // without one (a remote engine, an in-process test engine) nothing is waited for or killed.
  void attach(std::unique_ptr<transport::EngineChannel> channel, launch::ChildProcess process = {});
  // Shared-memory arenas for blobs to and from a local engine (see transport/blobs.h).
  void create_arenas(size_t bytes_each);
  int out_arena_fd() const { return out_arena_.fd(); }
  int in_arena_fd() const { return in_arena_.fd(); }
  // Reads blobs of this engine's replies; writes blobs of datapacks sent to it.
  const datapack::BlobReader* blob_reader() const { return &reader_; }
  datapack::BlobWriter* blob_writer();
  // Reads the blobs blob_writer() wrote (the datapacks sent to it, until they are sent).
  const datapack::BlobReader* sent_blob_reader() const { return &sent_reader_; }
  bool connected() const { return channel_ != nullptr; }
  bool busy() const { return busy_; }

  // Starts a call bounded by EngineCommandTimeout (or `timeout_s` when > 0).
  void start(const engine::Request& request, const char* what, double timeout_s = 0);
  // Collects the reply. Throws EngineError on an engine error, crash, hang, or interrupt.
  void finish(engine::Reply* reply);
  // The coordinator held the loop for `ns` (a viewer paused the run): the call in flight's
  // deadline and round trip start that much later.
  void postpone(int64_t ns);
  // start() + finish().
  void call(const engine::Request& request, const char* what, engine::Reply* reply,
            double timeout_s = 0);

  // Shuts the engine down: drains a call in flight, sends Shutdown, then reaps the process
  // (terminating it if it does not exit). Never throws; returns an error text or "".
  std::string shutdown(double timeout_s);
  // Last lines of the engine's log, for error messages.
  std::string log_tail(size_t lines = 20) const;

  // Loop bookkeeping.
  size_t index = 0;  // position in the config
  int64_t time_ns = 0;
  std::vector<engine::DataPackId> wanted;        // datapacks the functions read from it
  std::vector<engine::DataPackId> registered;    // what it said at Initialize it provides
  std::vector<engine::DataPack> pending_inputs;  // TF outputs for its next step
  int64_t call_started_ns = 0;
  int64_t last_roundtrip_ns = -1, last_compute_ns = -1;

 private:
  const config::EngineConfig& config_;
  std::filesystem::path log_file_;
  std::unique_ptr<transport::EngineChannel> channel_;
  launch::ChildProcess process_;
  transport::ShmArena out_arena_, in_arena_;
  transport::ShmBlobReader reader_{&out_arena_};
  transport::ShmBlobReader sent_reader_{&in_arena_};
  std::unique_ptr<transport::ShmBlobWriter> shm_writer_;
  datapack::InlineBlobWriter inline_writer_;
  bool busy_ = false;
  std::string what_;
  double timeout_s_ = 0;
};

}  // namespace convoy::loop
