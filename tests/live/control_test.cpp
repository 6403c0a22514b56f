// Viewers controlling a live run: client channels (clientPublish), /convoy/control's
// commands and the pause gate, /convoy/status, /convoy/metrics and /convoy/infractions, and
// what a client gets for bad input (a status error; the run and the other clients go on).
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <thread>

#include "live/run_control.h"
#include "live/server.h"
#include "live_client.h"
#include "test_support/eventually.h"

namespace convoy::live {
namespace {

using testing::TestClient;
using json = nlohmann::json;

using test_support::eventually;

TEST(ControlParsing, ClientChannelsAndMessages) {
  auto r = parse_client_message(
      R"({"op":"advertise","channels":[{"id":1,"topic":"/convoy/control","encoding":"json","schemaName":"convoy.Control"}]})");
  ASSERT_EQ(r.op, ClientRequest::Op::kAdvertise);
  ASSERT_EQ(r.advertise.size(), 1u);
  EXPECT_EQ(r.advertise[0].id, 1u);
  EXPECT_EQ(r.advertise[0].topic, "/convoy/control");
  EXPECT_EQ(r.advertise[0].encoding, "json");
  EXPECT_EQ(r.advertise[0].schema_name, "convoy.Control");
  r = parse_client_message(R"({"op":"unadvertise","channelIds":[1,2]})");
  ASSERT_EQ(r.op, ClientRequest::Op::kUnadvertise);
  EXPECT_EQ(r.unadvertise, (std::vector<uint32_t>{1, 2}));
  for (const char* bad :
       {R"({"op":"advertise"})", R"({"op":"advertise","channels":[3]})",
        R"({"op":"advertise","channels":[{"id":-1,"topic":"t","encoding":"json"}]})",
        R"({"op":"advertise","channels":[{"id":1,"encoding":"json"}]})",
        R"({"op":"advertise","channels":[{"id":1,"topic":5,"encoding":"json"}]})",
        R"({"op":"unadvertise","channelIds":["a"]})"}) {
    r = parse_client_message(bad);
    EXPECT_EQ(r.op, ClientRequest::Op::kInvalid) << bad;
    EXPECT_FALSE(r.error.empty()) << bad;
  }
  const std::string msg = std::string("\x01\x07\x00\x00\x00", 5) + R"({"command":"pause"})";
  ClientData d = parse_client_binary(msg);
  EXPECT_EQ(d.error, "");
  EXPECT_EQ(d.channel_id, 7u);
  EXPECT_EQ(d.payload, R"({"command":"pause"})");
  EXPECT_NE(parse_client_binary("").error, "");
  EXPECT_NE(parse_client_binary(std::string("\x02\x01\x00\x00\x00", 5)).error, "");
  EXPECT_NE(parse_client_binary(std::string("\x01\x01\x00", 3)).error, "");
}

TEST(ControlParsing, Commands) {
  EXPECT_EQ(parse_control(R"({"command":"pause"})").kind, ControlCommand::Kind::kPause);
  EXPECT_EQ(parse_control(R"({"command":"resume"})").kind, ControlCommand::Kind::kResume);
  EXPECT_EQ(parse_control(R"({"command":"step","extra":1})").kind, ControlCommand::Kind::kStep);
  for (const char* bad : {"", "not json", "[]", R"({"cmd":"pause"})", R"({"command":1})",
                          R"({"command":"rewind"})"}) {
    const ControlCommand c = parse_control(bad);
    EXPECT_EQ(c.kind, ControlCommand::Kind::kInvalid) << bad;
    EXPECT_NE(c.error.find("/convoy/control"), std::string::npos) << c.error;
  }
  EXPECT_NE(parse_control(R"({"command":"rewind"})").error.find("rewind"), std::string::npos);
}

class ControlTest : public ::testing::Test {
 protected:
  ControlTest() : server_(options()), control_(server_, gate_) {}

  static ServerOptions options() {
    ServerOptions o;
    o.address = parse_listen_address("0");
    o.info = {"convoy test", "s", {}, {"time", "clientPublish"}, {"json"}};
    return o;
  }
  // The id of `topic` in the client's first advertise.
  static uint32_t channel_of(const json& advertise, const std::string& topic) {
    for (const auto& c : advertise["channels"])
      if (c["topic"] == topic) return c["id"];
    ADD_FAILURE() << "no channel " << topic;
    return 0;
  }
  static void advertise_control(TestClient& c, uint32_t id) {
    c.send_text(json{{"op", "advertise"},
                     {"channels",
                      {{{"id", id},
                        {"topic", kControlTopic},
                        {"encoding", "json"},
                        {"schemaName", "convoy.Control"}}}}}
                    .dump());
  }
  static void send(TestClient& c, uint32_t channel, const std::string& payload) {
    std::string msg(1, '\x01');
    for (int i = 0; i < 4; ++i) msg.push_back(static_cast<char>((channel >> (8 * i)) & 0xff));
    c.send_binary(msg + payload);
  }
  // The next status error's message.
  static std::string next_error(TestClient& c) {
    const json s = c.next_op("status");
    EXPECT_EQ(s["level"], 2);
    return s["message"];
  }

  loop::PauseGate gate_;
  LiveServer server_;
  RunControl control_;
};

TEST_F(ControlTest, PauseStepAndResumeHoldTheGateAndTheStatusSaysSo) {
  TestClient client(server_.port());
  const json info = client.next_op("serverInfo");
  EXPECT_NE(std::find(info["capabilities"].begin(), info["capabilities"].end(), "clientPublish"),
            info["capabilities"].end());
  EXPECT_EQ(info["supportedEncodings"], json::array({"json"}));
  const json adv = client.next_op("advertise");
  client.subscribe(1, channel_of(adv, kStatusTopic));
  auto [sub, t, first] = client.next_data();  // latched: running at 0
  EXPECT_EQ(json::parse(first), (json{{"paused", false}, {"time_ns", 0}}));

  advertise_control(client, 5);
  gate_.wait(3000);  // the loop stands at 3 us
  send(client, 5, R"({"command":"pause"})");
  auto [s2, t2, paused] = client.next_data();
  EXPECT_EQ(json::parse(paused), (json{{"paused", true}, {"time_ns", 3000}}));
  EXPECT_TRUE(gate_.paused());

  std::atomic<int> cycles{0};
  std::thread loop([&] {
    for (int64_t time = 4000; time <= 6000; time += 1000) {
      gate_.wait(time);
      ++cycles;
    }
  });
  auto [s3, t3, held] = client.next_data();  // the loop stopped at 4 us
  EXPECT_EQ(json::parse(held), (json{{"paused", true}, {"time_ns", 4000}}));
  EXPECT_EQ(cycles.load(), 0);
  send(client, 5, R"({"command":"step"})");
  auto [s4, t4, stepped] = client.next_data();
  EXPECT_EQ(json::parse(stepped), (json{{"paused", true}, {"time_ns", 5000}}));
  EXPECT_EQ(cycles.load(), 1);
  send(client, 5, R"({"command":"resume"})");
  auto [s5, t5, resumed] = client.next_data();
  EXPECT_EQ(json::parse(resumed), (json{{"paused", false}, {"time_ns", 5000}}));
  loop.join();
  EXPECT_EQ(cycles.load(), 3);
  EXPECT_EQ(control_.commands(), 3u);
  EXPECT_EQ(server_.stats().at(0).errors, 0u);
}

TEST_F(ControlTest, BadInputGetsAStatusErrorAndTheClientCarriesOn) {
  TestClient bad(server_.port());
  TestClient other(server_.port());
  const json adv = other.next_op("advertise");
  other.subscribe(1, channel_of(adv, kStatusTopic));
  other.next_data();
  bad.next_op("advertise");

  bad.send_binary(std::string("\x07garbage", 8));
  EXPECT_NE(next_error(bad).find("opcode 7"), std::string::npos);
  bad.send_binary(std::string("\x01\x02", 2));
  EXPECT_NE(next_error(bad).find("channel id"), std::string::npos);
  send(bad, 9, R"({"command":"pause"})");
  EXPECT_NE(next_error(bad).find("not advertised"), std::string::npos);
  bad.send_text(
      R"({"op":"advertise","channels":[{"id":1,"topic":"/elsewhere","encoding":"json"}]})");
  EXPECT_NE(next_error(bad).find("/elsewhere"), std::string::npos);
  bad.send_text(
      R"({"op":"advertise","channels":[{"id":1,"topic":"/convoy/control","encoding":"cbor"}]})");
  EXPECT_NE(next_error(bad).find("cbor"), std::string::npos);
  bad.send_text(R"({"op":"advertise","channels":"x"})");
  EXPECT_NE(next_error(bad).find("channels"), std::string::npos);
  bad.send_text(R"({"op":"unadvertise","channelIds":[4]})");
  EXPECT_NE(next_error(bad).find("4"), std::string::npos);
  advertise_control(bad, 2);
  advertise_control(bad, 2);
  EXPECT_NE(next_error(bad).find("in use"), std::string::npos);
  send(bad, 2, "{not json");
  EXPECT_NE(next_error(bad).find("not JSON"), std::string::npos);
  send(bad, 2, R"({"command":"rewind"})");
  EXPECT_NE(next_error(bad).find("rewind"), std::string::npos);
  send(bad, 2, R"(["pause"])");
  EXPECT_NE(next_error(bad).find("expected"), std::string::npos);
  EXPECT_FALSE(gate_.paused());

  // Still a client: a good command works, and the other client sees it, without errors.
  send(bad, 2, R"({"command":"pause"})");
  auto [sub, t, paused] = other.next_data();
  EXPECT_EQ(json::parse(paused)["paused"], true);
  bad.send_text(R"({"op":"unadvertise","channelIds":[2]})");
  send(bad, 2, R"({"command":"resume"})");
  EXPECT_NE(next_error(bad).find("not advertised"), std::string::npos);
  EXPECT_TRUE(gate_.paused());
  const auto stats = server_.stats();
  ASSERT_EQ(stats.size(), 2u);
  EXPECT_EQ(stats[0].errors, 12u);
  EXPECT_EQ(stats[1].errors, 0u);
  gate_.close();
}

TEST_F(ControlTest, MetricsMergeAndInfractionsAreKeptForLateSubscribers) {
  EXPECT_TRUE(
      control_.publish(kMetricsTopic, R"({"driving_score":50,"route_completion":0.5})", 1000));
  EXPECT_TRUE(control_.publish(kMetricsTopic, R"({"driving_score":40})", 2000));
  EXPECT_TRUE(control_.publish(kInfractionsTopic, R"({"time_s":1.5,"kind":"red_light"})", 1500));
  EXPECT_TRUE(control_.publish(kInfractionsTopic, R"({"time_s":1.9,"kind":"collision"})", 1900));
  EXPECT_FALSE(control_.publish("/convoy/elsewhere", "{}", 0));
  EXPECT_FALSE(control_.publish(kMetricsTopic, "[1]", 0));
  EXPECT_EQ(control_.published(), 4u);
  TestClient client(server_.port());
  const json adv = client.next_op("advertise");
  client.subscribe(1, channel_of(adv, kMetricsTopic));
  auto [s1, t1, metrics] = client.next_data();
  EXPECT_EQ(t1, 2000u);
  EXPECT_EQ(json::parse(metrics),
            (json{{"driving_score", 40}, {"route_completion", 0.5}, {"time_ns", 2000}}));
  client.subscribe(2, channel_of(adv, kInfractionsTopic));
  auto [s2, t2, first] = client.next_data();
  EXPECT_EQ(json::parse(first)["kind"], "red_light");
  EXPECT_EQ(json::parse(first)["time_ns"], 1500);
  auto [s3, t3, second] = client.next_data();
  EXPECT_EQ(json::parse(second)["kind"], "collision");
}

}  // namespace
}  // namespace convoy::live
