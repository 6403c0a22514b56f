// FtiLoop::also_want(): a datapack no function reads, taken for the viewers (the live scene).
#include <gtest/gtest.h>

#include "fti_loop_fixture.h"

namespace convoy::loop {
namespace {

using namespace fti_fixture;  // NOLINT(build/namespaces): the fixture's helpers

class NotingTap final : public DataPackTap {
 public:
  std::vector<std::string> taken;
  void from_engine(const std::string& engine, const engine::DataPack& dp,
                   const datapack::BlobReader&, uint64_t, int64_t time_ns) override {
    taken.push_back(
        std::to_string(time_ns / ms(1)) + " " + engine + "/" + dp.id().name() + "=" +
        (dp.payload_case() == engine::DataPack::PAYLOAD_NOT_SET ? "empty" : dp.json_msgpack()));
  }
  void to_engine(const std::string&, const engine::DataPack&, const datapack::BlobReader&,
                 const LoadedFunction&, uint64_t, int64_t) override {}
  // The ones of datapack `name`.
  std::vector<std::string> of(const std::string& name) const {
    std::vector<std::string> out;
    for (const auto& t : taken)
      if (t.find("/" + name + "=") != std::string::npos) out.push_back(t);
    return out;
  }
};

// An engine without datapack `missing`: it answers it empty, as the engines answer an unknown
// id (EngineServer::get: the id and no payload).
class WithoutChannel final : public transport::EngineChannel {
 public:
  WithoutChannel(FakeEngine* engine, std::string missing)
      : inner_(engine), missing_(std::move(missing)) {}
  void start(const engine::Request& request, Deadline deadline) override {
    inner_.start(request, deadline);
  }
  transport::CallStatus finish(engine::Reply* reply, Deadline limit) override {
    const auto status = inner_.finish(reply, limit);
    auto blank = [&](engine::DataPack& dp) {
      if (dp.id().name() == missing_) dp.clear_payload();
    };
    if (reply->has_step())
      for (auto& dp : *reply->mutable_step()->mutable_outputs()) blank(dp);
    if (reply->has_get_datapacks())
      for (auto& dp : *reply->mutable_get_datapacks()->mutable_datapacks()) blank(dp);
    return status;
  }
  void postpone(SteadyClock::duration delay) override { inner_.postpone(delay); }
  void close() override {}
  std::string describe() const override { return inner_.describe(); }

 private:
  FakeChannel inner_;
  std::string missing_;
};

class FtiLoopAlsoWantTest : public FtiLoopTest {
 protected:
  // Makes the loop, asks for `extra` ("<engine>/<name>") and primes it.
  void start_with(const std::vector<std::pair<std::string, std::string>>& extra,
                  bool keep_observations = false) {
    std::vector<EngineHandle*> engines;
    for (auto& h : handles_) engines.push_back(h.get());
    loop_ = std::make_unique<FtiLoop>(engines, runner_, functions_, status_ ? &*status_ : nullptr);
    runner_.loop = loop_.get();
    for (const auto& [engine, name] : extra) added.push_back(loop_->also_want(engine, name));
    loop_->set_tap(&tap);
    loop_->keep_observations(keep_observations);
    loop_->prime();
  }
  // The world ("world", 2 ms: its car's link, read by a TF, and ego::road_user, read by no
  // function) and an agent ("agent", 3 ms: its state, read by no function, and a command).
  void world_and_agent() {
    add_engine("world", ms(2));
    add_engine("agent", ms(3));
    functions_ = {tf("tf_world", "world", {{"world", "link"}})};
    runner_.sends["tf_world"] = {id("agent", "cmd")};
  }
  std::vector<std::string> inputs(const std::string& engine) const {
    std::vector<std::string> out;
    for (const auto& f : fakes_)
      if (f.name == engine)
        for (const auto& s : f.steps)
          for (const auto& in : s.inputs) out.push_back(std::to_string(s.start_ns / ms(1)) + in);
    return out;
  }

  NotingTap tap;
  std::vector<bool> added;
};

TEST_F(FtiLoopAlsoWantTest, AnExtraDatapackComesAfterInitializeAndEveryStepToTheTapOnly) {
  world_and_agent();
  start_with({{"world", "ego::road_user"}, {"agent", "state"}});
  loop_->run(ms(6));
  EXPECT_EQ(added, (std::vector<bool>{true, true}));
  EXPECT_EQ(tap.of("ego::road_user"),
            (std::vector<std::string>{
                "0 world/ego::road_user=world@0", "2 world/ego::road_user=world@2",
                "4 world/ego::road_user=world@4", "6 world/ego::road_user=world@6"}));
  EXPECT_EQ(tap.of("state"),
            (std::vector<std::string>{"0 agent/state=agent@0", "3 agent/state=agent@3",
                                      "6 agent/state=agent@6"}));
  // The functions see what they read, as without it.
  EXPECT_EQ(runner_.seen,
            (std::vector<std::string>{
                "0 tf_world world/link=world@0 updated", "2 tf_world world/link=world@2 updated",
                "4 tf_world world/link=world@4 updated", "6 tf_world world/link=world@6 updated"}));
  EXPECT_EQ(inputs("agent"),
            (std::vector<std::string>{"0agent/cmd=tf_world@0", "3agent/cmd=tf_world@2"}));
}

TEST_F(FtiLoopAlsoWantTest, WithOrWithoutAnExtraDatapackTheFunctionsAndEnginesGetTheSame) {
  std::vector<std::string> calls[2], seen[2], to_agent[2], taken[2];
  for (int extra = 0; extra < 2; ++extra) {
    TearDown();
    handles_.clear();
    fakes_.clear();
    configs_.clear();
    runner_ = FakeRunner();
    tap.taken.clear();
    world_and_agent();
    status_ = sf({{"agent", "pos"}});
    if (extra)
      start_with({{"world", "ego::road_user"}, {"agent", "state"}});
    else
      start_with({});
    loop_->run(ms(12));
    calls[extra] = runner_.calls;
    seen[extra] = runner_.seen;
    to_agent[extra] = inputs("agent");
    for (const auto& t : tap.taken)
      if (t.find("road_user") == std::string::npos && t.find("/state=") == std::string::npos)
        taken[extra].push_back(t);
  }
  EXPECT_EQ(calls[0], calls[1]);
  EXPECT_EQ(seen[0], seen[1]);
  EXPECT_EQ(to_agent[0], to_agent[1]);
  EXPECT_EQ(taken[0], taken[1]);
  EXPECT_FALSE(seen[0].empty());
}

TEST_F(FtiLoopAlsoWantTest, ADatapackAFunctionReadsIsAskedForOnceAndStaysAnObservation) {
  add_engine("world", ms(2));
  status_ = sf({{"world", "link"}});
  start_with({{"world", "link"}, {"world", "ego::road_user"}, {"world", "ego::road_user"}},
             /*keep_observations=*/true);
  EXPECT_EQ(added, (std::vector<bool>{false, true, false}));
  ASSERT_EQ(handles_[0]->wanted.size(), 2u);
  EXPECT_EQ(handles_[0]->wanted[0].name(), "link");
  EXPECT_EQ(handles_[0]->wanted[1].name(), "ego::road_user");
  // prime()'s observations are the functions' inputs only.
  EXPECT_EQ(observations(), (std::vector<std::string>{"world/link=world@0"}));
  EXPECT_EQ(tap.of("ego::road_user"), (std::vector<std::string>{"0 world/ego::road_user=world@0"}));
}

TEST_F(FtiLoopAlsoWantTest, AnEngineWithoutTheDatapackAnswersItEmptyAndTheRunGoesOn) {
  auto& cfg = configs_.emplace_back();
  cfg.name = "robot";
  cfg.timestep_ns = ms(2);
  cfg.command_timeout_s = 5;
  auto& fake = fakes_.emplace_back();
  fake.name = "robot";
  handles_.push_back(std::make_unique<EngineHandle>(cfg, ""));
  handles_.back()->attach(std::make_unique<WithoutChannel>(&fake, "robot::road_user"));
  functions_ = {tf("tf_robot", "robot", {{"robot", "link"}})};
  start_with({{"robot", "robot::road_user"}});
  EXPECT_NO_THROW(loop_->run(ms(4)));
  EXPECT_EQ(loop_->sim_time_ns(), ms(4));
  EXPECT_EQ(
      tap.of("robot::road_user"),
      (std::vector<std::string>{"0 robot/robot::road_user=empty", "2 robot/robot::road_user=empty",
                                "4 robot/robot::road_user=empty"}));
  EXPECT_EQ(runner_.seen.back(), "4 tf_robot robot/link=robot@4 updated");
}

TEST_F(FtiLoopAlsoWantTest, AnUnknownEngineIsAnError) {
  add_engine("world", ms(2));
  std::vector<EngineHandle*> engines{handles_[0].get()};
  FtiLoop loop(engines, runner_, functions_);
  EXPECT_THROW(loop.also_want("nobody", "x::road_user"), std::invalid_argument);
  EXPECT_TRUE(handles_[0]->wanted.empty());
}

}  // namespace
}  // namespace convoy::loop
