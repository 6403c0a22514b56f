// FtiLoop with in-process fake engines and a fake function runner: no processes, no Python.
#include "loop/fti_loop.h"

#include <gtest/gtest.h>

#include <chrono>
#include <functional>
#include <list>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "core/error.h"
#include "loop/engine_handle.h"
#include "loop/function_runner.h"
#include "transport/engine_channel.h"

namespace convoy::loop {
namespace {

constexpr int64_t ms(int64_t n) { return n * 1'000'000; }

// "<engine>@<ms>": the payload an engine gives the datapacks it produces at a time.
std::string stamp(const std::string& engine, int64_t time_ns) {
  return engine + "@" + std::to_string(time_ns / ms(1));
}

// A simulated engine: steps by the requested duration and answers at once.
struct FakeEngine {
  struct Step {
    int64_t start_ns, duration_ns;
    std::vector<std::string> inputs;  // "<engine>/<name>=<payload>"
  };

  std::string name;
  int64_t time_ns = 0;
  std::vector<Step> steps;
  // Whether the engine has datapack `dp` at `time_ns`; one it does not have is left out of
  // its reply (an unchanged datapack).
  std::function<bool(const std::string& dp, int64_t time_ns)> produces = [](auto&, auto) {
    return true;
  };
  int64_t hang_at_ns = -1;  // never answers the step that starts then
  int64_t fail_at_ns = -1;  // answers the step that starts then with an error
  bool saw_shutdown = false;
  int resets = 0;
  std::vector<std::string> set_before_reset;  // SetDataPacks: "<name>=<payload>"

  void add_outputs(const google::protobuf::RepeatedPtrField<engine::DataPackId>& ids,
                   google::protobuf::RepeatedPtrField<engine::DataPack>* out) const {
    for (const auto& id : ids) {
      if (!produces(id.name(), time_ns)) continue;
      auto* dp = out->Add();
      *dp->mutable_id() = id;
      dp->set_json_msgpack(stamp(name, time_ns));
    }
  }

  // Returns false if the engine does not answer.
  bool handle(const engine::Request& request, engine::Reply* reply) {
    if (request.has_get_datapacks()) {
      add_outputs(request.get_datapacks().ids(),
                  reply->mutable_get_datapacks()->mutable_datapacks());
    } else if (request.has_step()) {
      const auto& step = request.step();
      Step record{time_ns, step.duration_ns(), {}};
      for (const auto& dp : step.inputs()) {
        record.inputs.push_back(dp.id().engine_name() + "/" + dp.id().name() + "=" +
                                dp.json_msgpack());
      }
      steps.push_back(record);
      if (record.start_ns == hang_at_ns) return false;
      if (record.start_ns == fail_at_ns) {
        reply->set_error("boom at " + std::to_string(time_ns));
        return true;
      }
      time_ns += step.duration_ns();
      reply->mutable_step()->set_time_ns(time_ns);
      add_outputs(step.wanted(), reply->mutable_step()->mutable_outputs());
    } else if (request.has_set_datapacks()) {
      for (const auto& dp : request.set_datapacks().datapacks())
        set_before_reset.push_back(dp.id().name() + "=" + dp.json_msgpack());
      reply->mutable_done();
    } else if (request.has_reset()) {
      ++resets;
      time_ns = 0;
      reply->mutable_done();
    } else if (request.has_shutdown()) {
      saw_shutdown = true;
      reply->mutable_done();
    }
    return true;
  }
};

class FakeChannel final : public transport::EngineChannel {
 public:
  explicit FakeChannel(FakeEngine* engine) : engine_(engine) {}
  void start(const engine::Request& request, Deadline deadline) override {
    deadline_ = deadline;
    reply_.Clear();
    answers_ = engine_->handle(request, &reply_);
  }
  transport::CallStatus finish(engine::Reply* reply, Deadline limit) override {
    if (!answers_) {
      Deadline until = std::min(deadline_, limit);
      if (until == Deadline::max()) {
        ADD_FAILURE() << "waiting without a deadline for engine " << engine_->name;
        return transport::CallStatus::kClosed;
      }
      std::this_thread::sleep_until(until);
      return transport::CallStatus::kTimeout;
    }
    reply->Swap(&reply_);
    return transport::CallStatus::kOk;
  }
  void close() override {}
  std::string describe() const override { return "in-process " + engine_->name; }

 private:
  FakeEngine* engine_;
  engine::Reply reply_;
  bool answers_ = true;
  Deadline deadline_ = Deadline::max();
};

// Records what the loop runs; transceiver functions return the datapacks in `sends`.
class FakeRunner final : public FunctionRunner {
 public:
  const FtiLoop* loop = nullptr;
  std::vector<std::string> calls;  // "<ms> <function>", one "<ms> |" per cycle start
  std::vector<std::string> seen;   // "<ms> <function> <engine>/<name>=<payload> [updated]"
  std::map<std::string, std::vector<engine::DataPackId>> sends;  // by function name
  int64_t done_at = -1;  // the status function returns done at this iteration
  int resets = 0;

  void begin_cycle() override { calls.push_back(now() + " |"); }
  bool run_status(const LoadedFunction& fn, const InputSource& src,
                  std::vector<engine::DataPack>* observations) override {
    record(fn, src);
    calls.back() += "#" + std::to_string(src.iteration);
    observations->emplace_back();
    observations->back().set_json_msgpack("obs#" + std::to_string(src.iteration));
    return static_cast<int64_t>(src.iteration) == done_at;
  }
  void reset() override { ++resets; }
  void run_preprocessing(const LoadedFunction& fn, const InputSource& src) override {
    record(fn, src);
  }
  void run_transceiver(const LoadedFunction& fn, const InputSource& src,
                       std::vector<engine::DataPack>* outputs) override {
    record(fn, src);
    for (const auto& id : sends[fn.name]) {
      outputs->emplace_back();
      *outputs->back().mutable_id() = id;
      outputs->back().set_json_msgpack(fn.name + "@" + now());
    }
  }

 private:
  std::string now() const { return std::to_string(loop->sim_time_ns() / ms(1)); }
  void record(const LoadedFunction& fn, const InputSource& src) {
    calls.push_back(now() + " " + fn.name);
    for (const auto& in : fn.inputs) {
      const engine::DataPack* dp = src.engine_datapack(in.engine, in.datapack);
      std::string s = now() + " " + fn.name + " " + in.engine + "/" + in.datapack + "=";
      s += dp ? dp->json_msgpack() : "none";
      if (dp && src.updated(in.engine, in.datapack)) s += " updated";
      seen.push_back(s);
    }
  }
};

LoadedFunction tf(const std::string& name, const std::string& engine,
                  std::vector<std::pair<std::string, std::string>> inputs = {}) {
  LoadedFunction fn;
  fn.name = name;
  fn.file = name + ".py";
  fn.engine = engine;
  for (auto& [eng, dp] : inputs) fn.inputs.push_back({dp, dp, eng, false});
  return fn;
}

LoadedFunction sf(std::vector<std::pair<std::string, std::string>> inputs = {}) {
  LoadedFunction fn = tf("status", "", std::move(inputs));
  fn.status = true;
  return fn;
}

LoadedFunction pf(const std::string& name, const std::string& engine,
                  std::vector<std::pair<std::string, std::string>> inputs = {}) {
  LoadedFunction fn = tf(name, engine, std::move(inputs));
  fn.preprocessing = true;
  return fn;
}

engine::DataPackId id(const std::string& engine, const std::string& name) {
  engine::DataPackId i;
  i.set_engine_name(engine);
  i.set_name(name);
  return i;
}

std::vector<int64_t> step_starts_ms(const FakeEngine& e) {
  std::vector<int64_t> out;
  for (const auto& s : e.steps) out.push_back(s.start_ns / ms(1));
  return out;
}

class FtiLoopTest : public ::testing::Test {
 protected:
  FakeEngine& add_engine(const std::string& name, int64_t timestep_ns, double timeout_s = 5) {
    auto& cfg = configs_.emplace_back();
    cfg.name = name;
    cfg.timestep_ns = timestep_ns;
    cfg.command_timeout_s = timeout_s;
    auto& fake = fakes_.emplace_back();
    fake.name = name;
    handles_.push_back(std::make_unique<EngineHandle>(cfg, ""));
    handles_.back()->attach(std::make_unique<FakeChannel>(&fake));
    return fake;
  }

  // Makes and primes the loop.
  void start(bool keep_observations = false) {
    std::vector<EngineHandle*> engines;
    for (auto& h : handles_) engines.push_back(h.get());
    loop_ = std::make_unique<FtiLoop>(engines, runner_, functions_, status_ ? &*status_ : nullptr);
    runner_.loop = loop_.get();
    loop_->keep_observations(keep_observations);
    loop_->prime();
  }

  // Primes and runs the loop until `until_ns`.
  void run(int64_t until_ns) {
    start();
    loop_->run(until_ns);
  }

  std::vector<std::string> observations() {
    std::vector<std::string> out;
    for (const auto& dp : loop_->take_observations())
      out.push_back(dp.id().engine_name() + "/" + dp.id().name() + "=" + dp.json_msgpack());
    return out;
  }

  // Runs and returns the EngineError the loop ends with.
  EngineError run_expecting_engine_error(int64_t until_ns) {
    try {
      run(until_ns);
    } catch (const EngineError& e) {
      return e;
    }
    ADD_FAILURE() << "the loop ended without an EngineError";
    return EngineError("", "");
  }

  void TearDown() override {
    for (auto& h : handles_) h->shutdown(1.0);
  }

  std::list<config::EngineConfig> configs_;  // stable addresses: handles keep references
  std::list<FakeEngine> fakes_;
  std::vector<std::unique_ptr<EngineHandle>> handles_;
  std::vector<LoadedFunction> functions_;
  std::optional<LoadedFunction> status_;
  FakeRunner runner_;
  std::unique_ptr<FtiLoop> loop_;
};

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
