#include "live/server.h"

#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include "live_client.h"
#include "test_support/eventually.h"

namespace convoy::live {
namespace {

using testing::TestClient;
using json = nlohmann::json;
namespace beast = boost::beast;
namespace net = boost::asio;
using tcp = net::ip::tcp;

ServerOptions options(uint16_t port = 0) {
  ServerOptions o;
  o.address = parse_listen_address(std::to_string(port));
  o.info = {"convoy test", "session-1", {{"simulation", "t"}}, {"time"}, {}};
  return o;
}

std::shared_ptr<const std::string> text(const std::string& s) {
  return std::make_shared<const std::string>(s);
}

using test_support::eventually;

TEST(LiveServer, GreetsAdvertisesAndSendsWhatIsSubscribed) {
  LiveServer server(options());
  const uint32_t a = server.add_channel({0, "eng/a", "json", "X", "{}", "jsonschema"});
  TestClient client(server.port());
  const auto info = client.next_op("serverInfo");
  EXPECT_EQ(info["name"], "convoy test");
  EXPECT_EQ(info["sessionId"], "session-1");
  const auto adv = client.next_op("advertise");
  ASSERT_EQ(adv["channels"].size(), 1u);
  EXPECT_EQ(adv["channels"][0]["id"], a);
  EXPECT_EQ(adv["channels"][0]["topic"], "eng/a");
  // A channel added later is advertised to connected clients.
  const uint32_t b = server.add_channel({0, "eng/b", "json", "X", "{}", "jsonschema"});
  EXPECT_EQ(client.next_op("advertise")["channels"][0]["id"], b);

  server.publish(a, 5, text("not subscribed yet"));
  client.subscribe(42, a);
  ASSERT_TRUE(eventually([&] { return server.has_subscribers(a); }));
  EXPECT_FALSE(server.has_subscribers(b));
  server.publish_time(1000);
  server.publish(a, 1000, text(R"({"x":1})"));
  auto [sub, t, payload] = client.next_data();
  EXPECT_EQ(sub, 42u);
  EXPECT_EQ(t, 1000u);
  EXPECT_EQ(payload, R"({"x":1})");

  client.send_text(R"({"op":"unsubscribe","subscriptionIds":[42]})");
  ASSERT_TRUE(eventually([&] { return !server.has_subscribers(a); }));
  server.stop(0.2);  // the test client does not answer the close
  const auto stats = server.stats();
  ASSERT_EQ(stats.size(), 1u);
  EXPECT_EQ(stats[0].queued, 2u);  // the time and the message
  EXPECT_EQ(stats[0].dropped, 0u);
  EXPECT_EQ(stats[0].errors, 0u);
}

TEST(LiveServer, SendsTheTime) {
  LiveServer server(options());
  TestClient client(server.port());
  client.next_op("advertise");
  server.publish_time(7);
  server.publish_time(7);  // not again
  server.publish_time(9);
  for (uint64_t want : {7u, 9u}) {
    auto [binary, bytes] = client.next();
    ASSERT_TRUE(binary);
    ASSERT_EQ(bytes.size(), 9u);
    EXPECT_EQ(static_cast<uint8_t>(bytes[0]), kOpTime);
    EXPECT_EQ(read_u64_le(bytes, 1), want);
  }
}

TEST(LiveServer, BadRequestsGetAStatusErrorAndOthersCarryOn) {
  LiveServer server(options());
  const uint32_t a = server.add_channel({0, "eng/a", "json", "X", "{}", "jsonschema"});
  TestClient bad(server.port()), good(server.port());
  bad.next_op("advertise");
  good.next_op("advertise");
  good.subscribe(1, a);
  bad.send_text("this is not json");
  auto s = bad.next_op("status");
  EXPECT_EQ(s["level"], 2);
  EXPECT_NE(s["message"].get<std::string>().find("not a JSON message"), std::string::npos);
  bad.subscribe(1, 999);
  s = bad.next_op("status");
  EXPECT_NE(s["message"].get<std::string>().find("unknown channel id 999"), std::string::npos);
  bad.send_text(R"({"op":"setParameters","parameters":[]})");
  EXPECT_NE(bad.next_op("status")["message"].get<std::string>().find("unsupported"),
            std::string::npos);
  bad.send_binary(std::string("\x01\x00\x00\x00\x00", 5));
  EXPECT_NE(bad.next_op("status")["message"].get<std::string>().find("client publishing"),
            std::string::npos);
  ASSERT_TRUE(eventually([&] { return server.has_subscribers(a); }));
  server.publish(a, 1, text("still here"));
  EXPECT_EQ(std::get<2>(good.next_data()), "still here");
  const auto stats = server.stats();
  ASSERT_EQ(stats.size(), 2u);
  EXPECT_EQ(stats[0].errors, 4u);
  EXPECT_EQ(stats[1].errors, 0u);
}

TEST(LiveServer, LatchedMessagesGoToLateSubscribers) {
  LiveServer server(options());
  const uint32_t log =
      server.add_channel({0, "/convoy/log", "json", "foxglove.Log", "{}", "jsonschema"}, 2);
  for (int i = 0; i < 3; ++i) server.publish(log, i, text("line " + std::to_string(i)));
  TestClient client(server.port());
  client.subscribe(3, log);
  EXPECT_EQ(std::get<2>(client.next_data()), "line 1");
  EXPECT_EQ(std::get<2>(client.next_data()), "line 2");
}

TEST(LiveServer, ASlowClientLosesTheOldestMessagesAndTheSimulationDoesNotWait) {
  ServerOptions o = options();
  o.limits = {/*max_messages=*/4, /*max_bytes=*/size_t{1} << 30};
  LiveServer server(o);
  const uint32_t a = server.add_channel({0, "big", "json", "X", "{}", "jsonschema"});
  TestClient slow(server.port());
  slow.next_op("advertise");
  slow.subscribe(0, a);
  ASSERT_TRUE(eventually([&] { return server.has_subscribers(a); }));
  const auto payload = text(std::string(1 << 20, 'x'));
  const auto t0 = std::chrono::steady_clock::now();
  for (int i = 0; i < 200; ++i) server.publish(a, i, payload);  // 200 MB; the client reads none
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_LT(s, 1.0);
  const auto stats = server.stats();
  ASSERT_EQ(stats.size(), 1u);
  EXPECT_EQ(stats[0].queued, 200u);
  EXPECT_GT(stats[0].dropped, 150u);
}

TEST(LiveServer, DisconnectingClientsAreForgotten) {
  LiveServer server(options());
  const uint32_t a = server.add_channel({0, "a", "json", "X", "{}", "jsonschema"});
  {
    TestClient client(server.port());
    client.subscribe(0, a);
    ASSERT_TRUE(eventually([&] { return server.has_subscribers(a); }));
    beast::get_lowest_layer(client.ws()).close();  // mid-conversation, no close frame
  }
  ASSERT_TRUE(eventually([&] { return !server.has_subscribers(a); }));
  server.publish(a, 1, text("nobody"));
  EXPECT_FALSE(server.stats().at(0).connected);
}

TEST(LiveServer, APortInUseOrANonLoopbackAddressIsRefusedWithTheOption) {
  LiveServer first(options());
  try {
    LiveServer second(options(first.port()));
    ADD_FAILURE() << "a second server bound the same port";
  } catch (const std::runtime_error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("--live 127.0.0.1:" + std::to_string(first.port())), std::string::npos) << m;
    EXPECT_NE(m.find("cannot listen there"), std::string::npos) << m;
  }
  ServerOptions o = options();
  o.address = parse_listen_address("0.0.0.0:0");
  EXPECT_THROW(LiveServer{o}, std::invalid_argument);
}

TEST(LiveServer, PlainHttpGetsAPageAndAWrongSubprotocolIsRefused) {
  LiveServer server(options());
  {
    net::io_context io;
    beast::tcp_stream stream(io);
    tcp::resolver resolver(io);
    stream.connect(resolver.resolve("127.0.0.1", std::to_string(server.port())));
    beast::http::request<beast::http::empty_body> req{beast::http::verb::get, "/", 11};
    req.set(beast::http::field::host, "127.0.0.1");
    beast::http::write(stream, req);
    beast::flat_buffer b;
    beast::http::response<beast::http::string_body> res;
    beast::http::read(stream, b, res);
    EXPECT_EQ(res.result_int(), 200);
    EXPECT_NE(res.body().find(server.url()), std::string::npos) << res.body();
  }
  EXPECT_THROW(TestClient(server.port(), ""), boost::system::system_error);
  EXPECT_THROW(TestClient(server.port(), "other.protocol"), boost::system::system_error);
}

}  // namespace
}  // namespace convoy::live
