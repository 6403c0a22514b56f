// FtiLoop: cycles, functions, timeouts, status function, advance and reset (fti_loop_fixture.h).
#include <gtest/gtest.h>

#include "fti_loop_fixture.h"

namespace convoy::loop {
namespace {

using namespace fti_fixture;  // NOLINT(build/namespaces): the fixture's helpers

TEST_F(FtiLoopTest, RunsPreprocessingThenTransceiverFunctionsOfDueEnginesInConfigOrder) {
  add_engine("a", ms(2));
  add_engine("b", ms(2));
  add_engine("c", ms(3));
  functions_ = {tf("tf_a1", "a"), pf("pf_b", "b"), tf("tf_c", "c"),
                pf("pf_a", "a"),  tf("tf_b", "b"), pf("pf_c", "c")};
  run(ms(6));
  // Every engine is due at 0 (the datapacks fetched after Initialize), then as it finishes.
  EXPECT_EQ(runner_.calls,
            (std::vector<std::string>{
                "0 |", "0 pf_b", "0 pf_a", "0 pf_c",  "0 tf_a1", "0 tf_c", "0 tf_b",  //
                "2 |", "2 pf_b", "2 pf_a", "2 tf_a1", "2 tf_b",                       //
                "3 |", "3 pf_c", "3 tf_c",                                            //
                "4 |", "4 pf_b", "4 pf_a", "4 tf_a1", "4 tf_b",                       //
                "6 |", "6 pf_b", "6 pf_a", "6 pf_c",  "6 tf_a1", "6 tf_c", "6 tf_b"}));
}

TEST_F(FtiLoopTest, StepsEachEngineWithItsOwnTimestepUntilTheTimeout) {
  auto& a = add_engine("a", ms(2));
  auto& b = add_engine("b", ms(3));
  run(ms(7));
  // Each step lasts the engine's timestep; none would end after the timeout.
  EXPECT_EQ(step_starts_ms(a), (std::vector<int64_t>{0, 2, 4}));
  EXPECT_EQ(step_starts_ms(b), (std::vector<int64_t>{0, 3}));
  for (const auto& s : a.steps) EXPECT_EQ(s.duration_ns, ms(2));
  for (const auto& s : b.steps) EXPECT_EQ(s.duration_ns, ms(3));
  // Cycles at 0 (both), 2 (a), 3 (b), 4 (a), 6 (both); then nothing is running.
  EXPECT_EQ(loop_->cycles(), 5u);
  EXPECT_EQ(loop_->sim_time_ns(), ms(6));
  EXPECT_EQ(a.time_ns, ms(6));
  EXPECT_EQ(b.time_ns, ms(6));
}

TEST_F(FtiLoopTest, AStepMayEndExactlyAtTheTimeout) {
  auto& a = add_engine("a", ms(2));
  auto& b = add_engine("b", ms(3));
  run(ms(9));
  EXPECT_EQ(step_starts_ms(a), (std::vector<int64_t>{0, 2, 4, 6}));
  EXPECT_EQ(step_starts_ms(b), (std::vector<int64_t>{0, 3, 6}));
  EXPECT_EQ(loop_->sim_time_ns(), ms(9));
}

TEST_F(FtiLoopTest, DeliversTransceiverOutputsWithTheTargetEnginesNextStep) {
  auto& a = add_engine("a", ms(2));
  auto& b = add_engine("b", ms(3));
  functions_ = {tf("tf_a", "a")};
  runner_.sends["tf_a"] = {id("b", "cmd")};
  run(ms(6));
  // tf_a runs at 0 ms, before b's first step, and at 2 ms, while b is busy until 3 ms:
  // b gets each output with the step it starts next.
  ASSERT_EQ(b.steps.size(), 2u);
  EXPECT_EQ(b.steps[0].inputs, (std::vector<std::string>{"b/cmd=tf_a@0"}));
  EXPECT_EQ(b.steps[1].inputs, (std::vector<std::string>{"b/cmd=tf_a@2"}));
  for (const auto& s : a.steps) EXPECT_TRUE(s.inputs.empty());
}

TEST_F(FtiLoopTest, ADatapackForAnUnknownEngineIsAFunctionError) {
  add_engine("a", ms(2));
  functions_ = {tf("tf_a", "a")};
  runner_.sends["tf_a"] = {id("nobody", "cmd")};
  try {
    run(ms(6));
    FAIL() << "no FunctionError";
  } catch (const FunctionError& e) {
    EXPECT_NE(std::string(e.what()).find("transceiver function 'tf_a'"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("'nobody'"), std::string::npos);
  }
}

TEST_F(FtiLoopTest, KeepsADatapackLeftOutOfAReplyAndReportsItNotUpdated) {
  auto& a = add_engine("a", ms(2));
  // "cam" comes every 4 ms from 4 ms on; "pos" with every step.
  a.produces = [](const std::string& dp, int64_t t) {
    return dp == "pos" || (t > 0 && t % ms(4) == 0);
  };
  functions_ = {tf("tf_a", "a", {{"a", "pos"}, {"a", "cam"}})};
  run(ms(8));
  // At 0 the functions see the datapacks fetched after Initialize, as updated.
  EXPECT_EQ(runner_.seen,
            (std::vector<std::string>{"0 tf_a a/pos=a@0 updated", "0 tf_a a/cam=none",         //
                                      "2 tf_a a/pos=a@2 updated", "2 tf_a a/cam=none",         //
                                      "4 tf_a a/pos=a@4 updated", "4 tf_a a/cam=a@4 updated",  //
                                      "6 tf_a a/pos=a@6 updated", "6 tf_a a/cam=a@4",          //
                                      "8 tf_a a/pos=a@8 updated", "8 tf_a a/cam=a@8 updated"}));
}

TEST_F(FtiLoopTest, AnEngineThatDoesNotAnswerWithinTheCommandTimeoutIsAnEngineError) {
  add_engine("a", ms(2));
  auto& b = add_engine("b", ms(3), /*timeout_s=*/0.05);
  b.hang_at_ns = ms(3);
  auto t0 = std::chrono::steady_clock::now();
  EngineError e = run_expecting_engine_error(ms(20));
  double waited = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_EQ(e.engine(), "b");
  EXPECT_NE(std::string(e.what()).find("engine 'b' did not answer Step within 0.05 s"),
            std::string::npos)
      << e.what();
  EXPECT_GE(waited, 0.05);
  EXPECT_LT(waited, 2.0);
  // b's hung step started at 3 ms; the loop stopped collecting it at 6 ms, after the cycle
  // of 4 ms.
  EXPECT_EQ(step_starts_ms(b), (std::vector<int64_t>{0, 3}));
  EXPECT_EQ(loop_->sim_time_ns(), ms(4));
}

TEST_F(FtiLoopTest, AnEngineErrorReplyIsAnEngineError) {
  auto& a = add_engine("a", ms(2));
  add_engine("b", ms(3));
  a.fail_at_ns = ms(4);
  EngineError e = run_expecting_engine_error(ms(20));
  EXPECT_EQ(e.engine(), "a");
  EXPECT_NE(std::string(e.what()).find("engine 'a' failed in Step:\nboom at 4000000"),
            std::string::npos)
      << e.what();
}

// The status function runs every cycle, after the transceiver functions, whichever engines
// are due; a datapack is updated in the cycles its engine delivered it (NRP-Core's isUpdated()).
TEST_F(FtiLoopTest, TheStatusFunctionRunsEveryCycleAfterTheTransceiverFunctions) {
  add_engine("a", ms(1));
  add_engine("b", ms(2));
  functions_ = {tf("tf_b", "b")};
  status_ = sf({{"a", "pos"}, {"b", "pos"}});
  run(ms(3));
  EXPECT_EQ(runner_.calls, (std::vector<std::string>{"0 |", "0 tf_b", "0 status#0",  //
                                                     "1 |", "1 status#1",            //
                                                     "2 |", "2 tf_b", "2 status#2",  //
                                                     "3 |", "3 status#3"}));
  EXPECT_EQ(runner_.seen, (std::vector<std::string>{
                              "0 status a/pos=a@0 updated", "0 status b/pos=b@0 updated",  //
                              "1 status a/pos=a@1 updated", "1 status b/pos=b@0",          //
                              "2 status a/pos=a@2 updated", "2 status b/pos=b@2 updated",  //
                              "3 status a/pos=a@3 updated", "3 status b/pos=b@2"}));
  EXPECT_FALSE(loop_->done());
}

TEST_F(FtiLoopTest, DoneEndsTheRunAfterItsCycleWithoutRestartingTheEngines) {
  auto& a = add_engine("a", ms(1));
  auto& b = add_engine("b", ms(2));
  status_ = sf();
  runner_.done_at = 2;
  run(ms(100));
  EXPECT_TRUE(loop_->done());
  EXPECT_EQ(loop_->cycles(), 3u);
  EXPECT_EQ(loop_->sim_time_ns(), ms(2));
  EXPECT_EQ(step_starts_ms(a), (std::vector<int64_t>{0, 1}));
  EXPECT_EQ(step_starts_ms(b), (std::vector<int64_t>{0}));
  // Nobody asked for them: nothing is kept.
  EXPECT_TRUE(observations().empty());
}

// NRP-Core's stepping: advance() runs the cycles due before its stop time and restarts every
// due engine; the status function's data collect until taken, done or not.
TEST_F(FtiLoopTest, AdvanceRunsTheCyclesBeforeItsStopTime) {
  auto& a = add_engine("a", ms(2));
  auto& b = add_engine("b", ms(3));
  status_ = sf({{"a", "pos"}});
  runner_.done_at = 1;
  start(/*keep_observations=*/true);
  EXPECT_EQ(observations(), (std::vector<std::string>{"a/pos=a@0"}))
      << "the datapacks fetched after Initialize come first";
  functions_.clear();
  loop_->advance(ms(2));
  EXPECT_EQ(loop_->sim_time_ns(), ms(2));
  EXPECT_EQ(loop_->cycles(), 1u);
  EXPECT_FALSE(loop_->done());
  loop_->advance(ms(4));  // cycles at 2 (a) and 3 (b)
  EXPECT_EQ(loop_->cycles(), 3u);
  EXPECT_FALSE(loop_->done()) << "done at cycle 1, not at cycle 2";
  EXPECT_EQ(observations(), (std::vector<std::string>{"/=obs#0", "/=obs#1", "/=obs#2"}));
  loop_->advance(ms(100));
  EXPECT_EQ(loop_->sim_time_ns(), ms(100));
  // Every due engine was restarted: no timeout bounds a stepped loop.
  EXPECT_EQ(step_starts_ms(a).back(), ms(98) / ms(1));
  EXPECT_EQ(step_starts_ms(b).back(), ms(99) / ms(1));
  std::atomic<bool> stop{true};
  loop_->advance(ms(200), &stop);
  EXPECT_EQ(loop_->sim_time_ns(), ms(100)) << "a stop request runs no cycle";
}

TEST_F(FtiLoopTest, TheStatusFunctionGetsNoDatapackBeforeItsEngineHasOne) {
  add_engine("b", ms(2)).produces = [](const std::string&, int64_t) { return false; };
  status_ = sf({{"b", "pos"}});
  run(ms(2));
  EXPECT_EQ(runner_.seen, (std::vector<std::string>{"0 status b/pos=none", "2 status b/pos=none"}));
}

TEST_F(FtiLoopTest, ClientInputsGoWithTheEnginesNextStepBeforeTransceiverOutputs) {
  auto& a = add_engine("a", ms(2));
  add_engine("b", ms(1));
  functions_ = {tf("tf_b", "b")};
  runner_.sends["tf_b"] = {id("a", "cmd")};
  start();
  engine::DataPack dp;
  *dp.mutable_id() = id("a", "cmd");
  dp.set_json_msgpack("client");
  loop_->add_input(dp);
  loop_->advance(ms(1));  // cycle at 0: a starts with both
  ASSERT_EQ(a.steps.size(), 1u);
  EXPECT_EQ(a.steps[0].inputs, (std::vector<std::string>{"a/cmd=client", "a/cmd=tf_b@0"}));
  *dp.mutable_id() = id("nobody", "cmd");
  EXPECT_THROW(loop_->add_input(dp), std::invalid_argument);
}

TEST_F(FtiLoopTest, ResetStartsAgainAtTimeZeroAndCycleZero) {
  auto& a = add_engine("a", ms(2));
  auto& b = add_engine("b", ms(3));
  status_ = sf({{"a", "pos"}});
  start(/*keep_observations=*/true);
  loop_->advance(ms(6));
  observations();
  engine::DataPack dp;
  *dp.mutable_id() = id("b", "reset_cmd");
  dp.set_json_msgpack("r");
  loop_->reset({dp});
  EXPECT_EQ(a.resets, 1);
  EXPECT_EQ(b.resets, 1);
  EXPECT_EQ(runner_.resets, 1);
  EXPECT_TRUE(a.set_before_reset.empty());
  EXPECT_EQ(b.set_before_reset, (std::vector<std::string>{"reset_cmd=r"}));
  EXPECT_EQ(loop_->sim_time_ns(), 0);
  EXPECT_EQ(loop_->cycles(), 0u);
  EXPECT_EQ(observations(), (std::vector<std::string>{"a/pos=a@0"}));
  runner_.calls.clear();
  loop_->advance(ms(2));
  EXPECT_EQ(runner_.calls, (std::vector<std::string>{"0 |", "0 status#0"}));
  EXPECT_EQ(step_starts_ms(a), (std::vector<int64_t>{0, 2, 4, 0}));
}

}  // namespace
}  // namespace convoy::loop
