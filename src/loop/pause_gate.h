// PauseGate: holds the loop between two cycles while a viewer has paused the run (the live
// server's /convoy/control: pause, resume, step). FtiLoop::set_gate() calls wait() before each
// cycle; it costs an atomic load while the run is not paused. A paused loop leaves the engines
// idle (their steps in flight complete and wait to be collected); FtiLoop moves their
// EngineCommandTimeout deadlines on by the time it was held.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>

namespace convoy::loop {

class PauseGate {
 public:
  // Called on each change the viewers should see: paused or not, and the simulated time the
  // loop stands at. Called under the gate's lock (from any thread): must not call the gate.
  using Listener = std::function<void(bool paused, int64_t time_ns)>;
  void set_listener(Listener listener);

  // The loop, between cycles, its simulated time `time_ns`: returns at once unless paused;
  // otherwise blocks until resume(), step(), close() or an interrupt (Ctrl-C). Returns the
  // wall time it was held, in ns.
  int64_t wait(int64_t time_ns);

  // Any thread.
  void pause();
  void resume();
  // One more cycle, then paused (from a running loop too).
  void step();
  // The run ends: never holds the loop again.
  void close();

  bool paused() const;
  int64_t time_ns() const { return time_ns_.load(std::memory_order_relaxed); }
  int64_t held_ns() const { return held_ns_.load(std::memory_order_relaxed); }

 private:
  void report();  // under mutex_

  std::atomic<bool> engaged_{false};  // paused_ or a step pending: wait() must look
  std::atomic<int64_t> time_ns_{0};
  std::atomic<int64_t> held_ns_{0};
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  bool paused_ = false, closed_ = false;
  int steps_ = 0;  // cycles to let through while paused
  Listener listener_;
  bool reported_ = false, reported_paused_ = false;
  int64_t reported_time_ = -1;
};

}  // namespace convoy::loop
