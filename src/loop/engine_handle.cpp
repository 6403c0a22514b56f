#include "loop/engine_handle.h"

#include <chrono>
#include <deque>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "core/clock.h"
#include "core/error.h"

namespace convoy::loop {

void EngineHandle::attach(std::unique_ptr<transport::EngineChannel> channel,
                          launch::ChildProcess process) {
  channel_ = std::move(channel);
  process_ = process;
}

void EngineHandle::create_arenas(size_t bytes_each) {
  out_arena_.create("convoy-" + name() + "-out", bytes_each);
  in_arena_.create("convoy-" + name() + "-in", bytes_each);
  shm_writer_ = std::make_unique<transport::ShmBlobWriter>(in_arena_);
}

datapack::BlobWriter* EngineHandle::blob_writer() {
  if (shm_writer_) return shm_writer_.get();
  return &inline_writer_;
}

void EngineHandle::start(const engine::Request& request, const char* what, double timeout_s) {
  if (!channel_) throw EngineError(name(), "engine '" + name() + "' is not connected");
  timeout_s_ = timeout_s > 0 ? timeout_s : config_.command_timeout_s;
  what_ = what;
  call_started_ns = now_ns();
  try {
    channel_->start(request, deadline_after(timeout_s_));
  } catch (const std::length_error& e) {
    // Only the datapacks the functions send make a request this large.
    throw FunctionError("engine '" + name() + "': " + what + ": " + e.what() +
                        " (the datapacks the functions sent to it)");
  }
  if (shm_writer_) shm_writer_->next_message();  // blobs of the next request go elsewhere
  busy_ = true;
}

void EngineHandle::finish(engine::Reply* reply) {
  busy_ = false;
  auto status = channel_->finish(reply);
  last_roundtrip_ns = now_ns() - call_started_ns;
  std::string prefix = "engine '" + name() + "' ";
  switch (status) {
    case transport::CallStatus::kOk:
      if (!reply->error().empty()) {
        const std::string message = prefix + "failed in " + what_ + ":\n" + reply->error();
        if (reply->user_error()) throw UserError(message);  // its input's fault: exit 2
        throw EngineError(name(), message);
      }
      return;
    case transport::CallStatus::kClosed: {
      std::string how = "closed its connection";
      if (process_.pid() > 0) {
        process_.wait_for(1.0);
        how = process_.describe();
        if (how == "still running") how = "closed its connection";
      }
      channel_.reset();
      throw EngineError(name(), prefix + "died during " + what_ + ": " + how + "\n--- " +
                                    log_file_.string() + " (last lines) ---\n" + log_tail());
    }
    case transport::CallStatus::kTimeout: {
      std::ostringstream s;
      s << prefix << "did not answer " << what_ << " within " << timeout_s_
        << " s (EngineCommandTimeout); it is considered hung\n--- " << log_file_.string()
        << " (last lines) ---\n"
        << log_tail();
      channel_.reset();  // the stream is out of step now
      throw EngineError(name(), s.str());
    }
    case transport::CallStatus::kInterrupted:
      busy_ = true;  // the reply may still come; shutdown() drains it
      throw EngineError(name(), "interrupted while waiting for engine '" + name() + "'");
  }
}

void EngineHandle::postpone(int64_t ns) {
  call_started_ns += ns;
  if (channel_) channel_->postpone(std::chrono::nanoseconds(ns));
}

void EngineHandle::call(const engine::Request& request, const char* what, engine::Reply* reply,
                        double timeout_s) {
  start(request, what, timeout_s);
  finish(reply);
}

std::string EngineHandle::shutdown(double timeout_s) {
  std::string error;
  bool responsive = channel_ != nullptr;  // false after a crash or a hang
  if (channel_) {
    try {
      engine::Reply reply;
      if (busy_) {
        // A call is still in flight (interrupt, or another engine failed): give it a moment.
        busy_ = false;
        if (channel_->finish(&reply, deadline_after(1.0)) != transport::CallStatus::kOk) {
          responsive = false;
          channel_.reset();
        }
      }
      if (channel_) {
        engine::Request request;
        request.mutable_shutdown();
        channel_->start(request, deadline_after(timeout_s));
        reply.Clear();
        auto status = channel_->finish(&reply);
        if (status == transport::CallStatus::kOk && !reply.error().empty()) {
          error = "engine '" + name() + "' failed in shutdown:\n" + reply.error();
        } else if (status != transport::CallStatus::kOk) {
          responsive = false;
          if (status == transport::CallStatus::kTimeout)
            error = "engine '" + name() + "' did not shut down within " +
                    std::to_string(timeout_s) + " s";
        }
      }
    } catch (const std::exception& e) {
      error = e.what();
    }
    if (channel_) channel_->close();
    channel_.reset();
  }
  if (process_.pid() > 0) {
    // A responsive engine exits by itself after Shutdown; a hung or broken one is ended.
    if (!responsive || !process_.wait_for(2.0)) process_.terminate(0.5);
    process_.terminate(0);  // reaps, and clears the process group
  }
  return error;
}

std::string EngineHandle::log_tail(size_t lines) const {
  std::ifstream in(log_file_);
  std::deque<std::string> tail;
  std::string line;
  while (std::getline(in, line)) {
    tail.push_back(line);
    if (tail.size() > lines) tail.pop_front();
  }
  std::string out;
  for (auto& l : tail) out += l + "\n";
  if (out.empty()) out = "(empty)\n";
  return out;
}

}  // namespace convoy::loop
