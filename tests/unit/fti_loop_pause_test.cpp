// FtiLoop with a PauseGate (loop/pause_gate.h): pause, step, resume, interrupt.
#include <gtest/gtest.h>

#include "fti_loop_fixture.h"
#include "test_support/eventually.h"

namespace convoy::loop {
namespace {

using namespace fti_fixture;  // NOLINT(build/namespaces): the fixture's helpers

using test_support::eventually;

TEST(PauseGate, PassesUnlessPausedAndStepsOneCycleAtATime) {
  PauseGate gate;
  std::mutex m;
  std::vector<std::string> changes;
  gate.set_listener([&](bool paused, int64_t t) {
    std::lock_guard<std::mutex> lock(m);
    changes.push_back((paused ? "paused@" : "running@") + std::to_string(t));
  });
  EXPECT_EQ(gate.wait(5), 0);
  gate.pause();
  std::atomic<int> passed{0};
  std::thread loop([&] {
    for (int t = 10; t <= 30; t += 10) {
      gate.wait(t);
      ++passed;
    }
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  EXPECT_EQ(passed.load(), 0);  // held at 10
  gate.step();
  ASSERT_TRUE(eventually([&] { return passed.load() == 1; }));
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  EXPECT_EQ(passed.load(), 1);  // one cycle, then held at 20
  EXPECT_TRUE(gate.paused());
  gate.resume();
  loop.join();
  EXPECT_EQ(passed.load(), 3);
  EXPECT_GE(gate.held_ns(), 150'000'000);
  std::lock_guard<std::mutex> lock(m);
  EXPECT_EQ(changes,
            (std::vector<std::string>{"paused@5", "paused@10", "paused@20", "running@20"}));
}

TEST(PauseGate, ACtrlCOrTheRunsEndReleasesAPausedLoop) {
  PauseGate gate;
  gate.pause();
  std::thread held([&] { gate.wait(0); });
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  interrupt_signal().store(2);
  held.join();  // hangs (the test times out) if the interrupt is not seen
  interrupt_signal().store(0);
  std::thread closed([&] { gate.wait(0); });
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  gate.close();
  closed.join();
  gate.pause();  // after the end: no effect
  EXPECT_EQ(gate.wait(1), 0);
}

TEST_F(FtiLoopTest, APausedLoopHoldsBetweenCyclesAndThePauseIsNoEngineTimeout) {
  auto& a = add_engine("a", ms(10), /*timeout_s=*/0.2);
  a.strict_deadline = true;  // as the socket channel: a late reply is a hung engine
  functions_ = {tf("tf_a", "a")};
  PauseGate gate;
  start();
  loop_->set_gate(&gate);
  gate.pause();
  std::string error;
  std::thread runner([&] {
    try {
      loop_->run(ms(50));
    } catch (const std::exception& e) {
      error = e.what();
    }
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  gate.step();  // the cycle at 0 (starts the step 0 -> 10 ms)
  gate.step();  // the cycle at 10
  ASSERT_TRUE(eventually([&] { return gate.time_ns() == ms(10); }));
  // Held at 10 ms with a step in flight for longer than its EngineCommandTimeout.
  std::this_thread::sleep_for(std::chrono::milliseconds(400));
  gate.resume();
  runner.join();
  EXPECT_EQ(error, "");
  EXPECT_EQ(loop_->sim_time_ns(), ms(50));
  EXPECT_EQ(step_starts_ms(a), (std::vector<int64_t>{0, 10, 20, 30, 40}));
  EXPECT_GE(gate.held_ns(), 400'000'000);
}

// also_want(): a datapack no function reads, taken for the viewers (the live scene).

// Notes what the loop takes from the engines: "<ms> <engine>/<name>=<payload>" ("empty" for an
// empty datapack).

}  // namespace
}  // namespace convoy::loop
