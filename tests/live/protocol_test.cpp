#include "live/protocol.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

namespace convoy::live {
namespace {

using json = nlohmann::json;

TEST(Protocol, ServerInfoHasTheSpecsFields) {
  const auto j =
      json::parse(server_info_json({"convoy", "123", {{"simulation", "x"}}, {"time"}, {}}));
  EXPECT_EQ(j["op"], "serverInfo");
  EXPECT_EQ(j["name"], "convoy");
  EXPECT_EQ(j["capabilities"], json::array({"time"}));
  EXPECT_TRUE(j["supportedEncodings"].is_array());
  EXPECT_EQ(j["metadata"]["simulation"], "x");
  EXPECT_EQ(j["sessionId"], "123");
}

TEST(Protocol, AdvertiseListsEveryFieldOfEachChannel) {
  const auto j = json::parse(
      advertise_json({{7, "cam/image", "json", "foxglove.CompressedImage", "{}", "jsonschema"}}));
  EXPECT_EQ(j["op"], "advertise");
  ASSERT_EQ(j["channels"].size(), 1u);
  const auto& c = j["channels"][0];
  EXPECT_EQ(c["id"], 7);
  EXPECT_EQ(c["topic"], "cam/image");
  EXPECT_EQ(c["encoding"], "json");
  EXPECT_EQ(c["schemaName"], "foxglove.CompressedImage");
  EXPECT_EQ(c["schema"], "{}");
  EXPECT_EQ(c["schemaEncoding"], "jsonschema");
  EXPECT_EQ(json::parse(advertise_json({}))["channels"], json::array());
}

TEST(Protocol, StatusAndUnadvertise) {
  const auto s = json::parse(status_json(StatusLevel::kError, "bad \xff bytes"));
  EXPECT_EQ(s["op"], "status");
  EXPECT_EQ(s["level"], 2);
  EXPECT_NE(s["message"].get<std::string>().find("bad"), std::string::npos);
  const auto u = json::parse(unadvertise_json({1, 2}));
  EXPECT_EQ(u["op"], "unadvertise");
  EXPECT_EQ(u["channelIds"], json::array({1, 2}));
}

TEST(Protocol, MessageDataHeaderIsLittleEndian) {
  const std::string h = message_data_header(0x04030201u, 0x0807060504030201ull);
  ASSERT_EQ(h.size(), kMessageDataHeaderBytes);
  EXPECT_EQ(static_cast<uint8_t>(h[0]), 0x01);
  for (int i = 0; i < 4; ++i) EXPECT_EQ(static_cast<uint8_t>(h[1 + i]), i + 1);
  for (int i = 0; i < 8; ++i) EXPECT_EQ(static_cast<uint8_t>(h[5 + i]), i + 1);
  EXPECT_EQ(read_u32_le(h, 1), 0x04030201u);
  EXPECT_EQ(read_u64_le(h, 5), 0x0807060504030201ull);
}

TEST(Protocol, TimeMessage) {
  const std::string t = time_message(1500000000ull);
  ASSERT_EQ(t.size(), 9u);
  EXPECT_EQ(static_cast<uint8_t>(t[0]), 0x02);
  EXPECT_EQ(read_u64_le(t, 1), 1500000000ull);
}

TEST(Protocol, ParsesSubscribeAndUnsubscribe) {
  auto r = parse_client_message(
      R"({"op":"subscribe","subscriptions":[{"id":0,"channelId":3},{"id":1,"channelId":5}]})");
  ASSERT_EQ(r.op, ClientRequest::Op::kSubscribe);
  ASSERT_EQ(r.subscribe.size(), 2u);
  EXPECT_EQ(r.subscribe[1].id, 1u);
  EXPECT_EQ(r.subscribe[1].channel_id, 5u);
  r = parse_client_message(R"({"op":"unsubscribe","subscriptionIds":[0, 4294967295]})");
  ASSERT_EQ(r.op, ClientRequest::Op::kUnsubscribe);
  EXPECT_EQ(r.unsubscribe, (std::vector<uint32_t>{0, 4294967295u}));
}

TEST(Protocol, GarbageIsInvalidWithAReason) {
  struct Case {
    const char* text;
    const char* says;
  } cases[] = {
      {"{not json", "not a JSON message"},
      {"[1,2]", "JSON object"},
      {R"({"subscriptions":[]})", "\"op\""},
      {R"({"op":"subscribe"})", "\"subscriptions\" must be an array"},
      {R"({"op":"subscribe","subscriptions":[{"id":-1,"channelId":1}]})", "\"id\" must be"},
      {R"({"op":"subscribe","subscriptions":[{"id":1,"channelId":4294967296}]})", "channelId"},
      {R"({"op":"subscribe","subscriptions":[{"id":1}]})", "missing \"channelId\""},
      {R"({"op":"subscribe","subscriptions":[{"id":1.5,"channelId":1}]})", "\"id\" must be"},
      {R"({"op":"unsubscribe","subscriptionIds":["a"]})", "subscription ids must be"},
  };
  for (const auto& c : cases) {
    const auto r = parse_client_message(c.text);
    EXPECT_EQ(r.op, ClientRequest::Op::kInvalid) << c.text;
    EXPECT_NE(r.error.find(c.says), std::string::npos) << c.text << " -> " << r.error;
  }
}

TEST(Protocol, OtherOperationsAreUnsupported) {
  const auto r = parse_client_message(R"({"op":"getParameters","parameterNames":[]})");
  EXPECT_EQ(r.op, ClientRequest::Op::kUnsupported);
  EXPECT_EQ(r.error, "getParameters");
}

}  // namespace
}  // namespace convoy::live
