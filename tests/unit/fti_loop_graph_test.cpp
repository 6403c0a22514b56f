// FtiLoop::set_graph(): the computational graph (DataPackProcessor "cg") runs once per cycle
// with the due engines, reads what also_want() took, and its datapacks reach their engines.
#include <gtest/gtest.h>

#include <algorithm>

#include "fti_loop_fixture.h"

namespace convoy::loop {
namespace {

using namespace fti_fixture;  // NOLINT(build/namespaces): the fixture's helpers

// A graph that relays "src/out" to "dst/in" when src is due, and records each call.
class FakeGraph final : public FunctionRunner {
 public:
  const FtiLoop* loop = nullptr;
  std::vector<std::string> calls;  // "<ms> <due engines> <src/out as read>"
  bool fail = false;

  void begin_cycle() override {}
  void run_preprocessing(const LoadedFunction&, const InputSource&) override { ADD_FAILURE(); }
  void run_transceiver(const LoadedFunction&, const InputSource&,
                       std::vector<engine::DataPack>*) override {
    ADD_FAILURE();
  }
  void run_graph(const std::vector<std::string>& due, const InputSource& src,
                 std::vector<engine::DataPack>* outputs) override {
    if (fail) throw FunctionError("node failed");
    std::string line = std::to_string(src.time_ns / ms(1)) + " ";
    for (const auto& e : due) line += e + ",";
    const engine::DataPack* dp = src.engine_datapack("src", "out");
    line += " " + (dp ? dp->json_msgpack() : std::string("none"));
    calls.push_back(line);
    if (std::find(due.begin(), due.end(), "src") == due.end() || !dp) return;
    outputs->emplace_back();
    *outputs->back().mutable_id() = id("dst", "in");
    outputs->back().set_json_msgpack("relayed " + dp->json_msgpack());
  }
};

class FtiLoopGraphTest : public FtiLoopTest {
 protected:
  void start_graph() {
    std::vector<EngineHandle*> engines;
    for (auto& h : handles_) engines.push_back(h.get());
    loop_ = std::make_unique<FtiLoop>(engines, graph_, functions_, nullptr);
    graph_.loop = loop_.get();
    label_.name = "computational graph (graph.py)";
    label_.file = "graph.py";
    loop_->also_want("src", "out");
    loop_->set_graph(&label_);
    loop_->prime();
  }
  FakeGraph graph_;
  LoadedFunction label_;
};

TEST_F(FtiLoopGraphTest, RunsEachCycleWithTheDueEnginesAndRoutesItsDatapacks) {
  add_engine("src", ms(2));
  FakeEngine& dst = add_engine("dst", ms(3));
  start_graph();
  loop_->run(ms(6));
  EXPECT_EQ(graph_.calls,
            (std::vector<std::string>{"0 src,dst, src@0", "2 src, src@2", "3 dst, src@2",
                                      "4 src, src@4", "6 src,dst, src@6"}));
  ASSERT_EQ(dst.steps.size(), 2u);
  EXPECT_EQ(dst.steps[0].inputs, (std::vector<std::string>{"dst/in=relayed src@0"}));
  // What the graph sent at 2 ms waits for dst's next step, at 3 ms; that of 4 ms, for the
  // step at 6 ms, which is past the end.
  EXPECT_EQ(dst.steps[1].inputs, (std::vector<std::string>{"dst/in=relayed src@2"}));
}

TEST_F(FtiLoopGraphTest, AnErrorInTheGraphEndsTheRun) {
  add_engine("src", ms(2));
  add_engine("dst", ms(2));
  start_graph();
  graph_.fail = true;
  EXPECT_THROW(loop_->run(ms(4)), FunctionError);
}

TEST_F(FtiLoopGraphTest, WithoutAGraphTheRunnerIsNeverAskedForOne) {
  add_engine("src", ms(2));
  std::vector<EngineHandle*> engines;
  for (auto& h : handles_) engines.push_back(h.get());
  loop_ = std::make_unique<FtiLoop>(engines, graph_, functions_, nullptr);
  graph_.loop = loop_.get();
  loop_->prime();
  loop_->run(ms(4));
  EXPECT_TRUE(graph_.calls.empty());
}

}  // namespace
}  // namespace convoy::loop
