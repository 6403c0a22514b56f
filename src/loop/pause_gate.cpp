#include "loop/pause_gate.h"

#include <chrono>

#include "core/clock.h"
#include "core/interrupt.h"

namespace convoy::loop {

void PauseGate::set_listener(Listener listener) {
  std::lock_guard<std::mutex> lock(mutex_);
  listener_ = std::move(listener);
}

void PauseGate::report() {
  const int64_t t = time_ns_.load(std::memory_order_relaxed);
  if (reported_ && reported_paused_ == paused_ && reported_time_ == t) return;
  reported_ = true;
  reported_paused_ = paused_;
  reported_time_ = t;
  if (listener_) listener_(paused_, t);
}

int64_t PauseGate::wait(int64_t time_ns) {
  time_ns_.store(time_ns, std::memory_order_relaxed);
  if (!engaged_.load(std::memory_order_acquire)) return 0;
  std::unique_lock<std::mutex> lock(mutex_);
  if (closed_ || !paused_) return 0;
  if (steps_ > 0) {  // a step: this cycle runs
    --steps_;
    reported_ = false;  // the viewers hear where it stops, even at the same time
    return 0;
  }
  report();  // where the loop stopped
  const int64_t start = now_ns();
  // A signal handler cannot notify a condition variable: look at the interrupt now and then.
  while (paused_ && steps_ == 0 && !closed_ && !interrupted())
    wake_.wait_for(lock, std::chrono::milliseconds(50));
  if (paused_ && steps_ > 0) {
    --steps_;
    reported_ = false;
  }
  const int64_t held = now_ns() - start;
  held_ns_.fetch_add(held, std::memory_order_relaxed);
  return held;
}

void PauseGate::pause() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (closed_) return;
  paused_ = true;
  steps_ = 0;
  engaged_.store(true, std::memory_order_release);
  report();
}

void PauseGate::resume() {
  std::lock_guard<std::mutex> lock(mutex_);
  paused_ = false;
  steps_ = 0;
  engaged_.store(false, std::memory_order_release);
  report();
  wake_.notify_all();
}

void PauseGate::step() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (closed_) return;
  if (!paused_) steps_ = 0;
  paused_ = true;
  ++steps_;  // two steps in quick succession: two cycles
  engaged_.store(true, std::memory_order_release);
  wake_.notify_all();
}

void PauseGate::close() {
  std::lock_guard<std::mutex> lock(mutex_);
  closed_ = true;
  paused_ = false;
  steps_ = 0;
  engaged_.store(false, std::memory_order_release);
  wake_.notify_all();
}

bool PauseGate::paused() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return paused_;
}

}  // namespace convoy::loop
