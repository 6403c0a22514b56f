// Splits a loop over independent items between the calling thread and one kept worker
// thread: for the per-frame loops (a camera frame's pixels) that run while the renderer's
// threads wait, so that the second core does not idle.
//
//   TwoWay split;                                      // starts its worker (if 2+ cores)
//   split.run(pixels, [&](size_t begin, size_t end) {  // f(0, mid) on the worker,
//     for (size_t i = begin; i < end; ++i) ...;         // f(mid, n) here
//   });                                                // returns when both halves are done
//
// The halves must touch disjoint data; f must not throw. On one core, or for fewer than
// `min_items`, f(0, n) runs here alone. The same output whatever the split: a split loop
// must compute each item on its own.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <functional>
#include <mutex>
#include <thread>

namespace convoy {

class TwoWay {
 public:
  explicit TwoWay(size_t min_items = 4096) : min_items_(min_items) {
    if (std::thread::hardware_concurrency() >= 2) worker_ = std::thread([this] { serve(); });
  }
  ~TwoWay() {
    if (!worker_.joinable()) return;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    wake_.notify_one();
    worker_.join();
  }
  TwoWay(const TwoWay&) = delete;
  TwoWay& operator=(const TwoWay&) = delete;

  // `align`: the worker's half ends on a multiple of it (for loops that go in blocks).
  void run(size_t n, const std::function<void(size_t, size_t)>& f, size_t align = 1) {
    size_t mid = n / 2;
    if (align > 1) mid -= mid % align;
    if (!worker_.joinable() || n < min_items_ || mid == 0) {
      f(0, n);
      return;
    }
    {
      std::lock_guard<std::mutex> lock(mutex_);
      job_ = &f;
      end_ = mid;
      pending_ = true;
    }
    wake_.notify_one();
    f(mid, n);
    std::unique_lock<std::mutex> lock(mutex_);
    done_.wait(lock, [this] { return !pending_; });
  }

 private:
  void serve() {
    std::unique_lock<std::mutex> lock(mutex_);
    for (;;) {
      wake_.wait(lock, [this] { return stop_ || (pending_ && job_); });
      if (stop_) return;
      const auto* job = job_;
      const size_t end = end_;
      job_ = nullptr;
      lock.unlock();
      (*job)(0, end);
      lock.lock();
      pending_ = false;
      done_.notify_one();
    }
  }

  size_t min_items_;
  std::mutex mutex_;
  std::condition_variable wake_, done_;
  const std::function<void(size_t, size_t)>* job_ = nullptr;
  size_t end_ = 0;
  bool pending_ = false, stop_ = false;
  std::thread worker_;
};

}  // namespace convoy
