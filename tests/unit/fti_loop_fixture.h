// FtiLoop's test fixture: in-process fake engines and a fake function runner (no processes, no
// Python), shared by fti_loop_test.cpp, fti_loop_pause_test.cpp and fti_loop_also_want_test.cpp.
#pragma once

#include <gtest/gtest.h>

#include <chrono>
#include <functional>
#include <list>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "core/error.h"
#include "core/interrupt.h"
#include "loop/engine_handle.h"
#include "loop/fti_loop.h"
#include "loop/function_runner.h"
#include "transport/engine_channel.h"

namespace convoy::loop::fti_fixture {

constexpr int64_t ms(int64_t n) { return n * 1'000'000; }

// "<engine>@<ms>": the payload an engine gives the datapacks it produces at a time.
inline std::string stamp(const std::string& engine, int64_t time_ns) {
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
  int64_t hang_at_ns = -1;       // never answers the step that starts then
  int64_t fail_at_ns = -1;       // answers the step that starts then with an error
  bool strict_deadline = false;  // a reply collected after the call's deadline is a timeout
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
    if (engine_->strict_deadline && SteadyClock::now() > deadline_)
      return transport::CallStatus::kTimeout;
    reply->Swap(&reply_);
    return transport::CallStatus::kOk;
  }
  void postpone(SteadyClock::duration delay) override {
    if (deadline_ != Deadline::max()) deadline_ += delay;
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

inline LoadedFunction tf(const std::string& name, const std::string& engine,
                         std::vector<std::pair<std::string, std::string>> inputs = {}) {
  LoadedFunction fn;
  fn.name = name;
  fn.file = name + ".py";
  fn.engine = engine;
  for (auto& [eng, dp] : inputs) fn.inputs.push_back({dp, dp, eng, false});
  return fn;
}

inline LoadedFunction sf(std::vector<std::pair<std::string, std::string>> inputs = {}) {
  LoadedFunction fn = tf("status", "", std::move(inputs));
  fn.status = true;
  return fn;
}

inline LoadedFunction pf(const std::string& name, const std::string& engine,
                         std::vector<std::pair<std::string, std::string>> inputs = {}) {
  LoadedFunction fn = tf(name, engine, std::move(inputs));
  fn.preprocessing = true;
  return fn;
}

inline engine::DataPackId id(const std::string& engine, const std::string& name) {
  engine::DataPackId i;
  i.set_engine_name(engine);
  i.set_name(name);
  return i;
}

inline std::vector<int64_t> step_starts_ms(const FakeEngine& e) {
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

}  // namespace convoy::loop::fti_fixture
