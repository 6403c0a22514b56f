// A synchronous Foxglove WebSocket client for the tests (Boost.Beast), with a 5 s read timeout
// so that a missing message fails the test instead of hanging it.
#pragma once

#include <boost/asio/connect.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <chrono>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <utility>

#include "live/protocol.h"

namespace convoy::live::testing {

namespace beast = boost::beast;
namespace net = boost::asio;
using tcp = net::ip::tcp;

class TestClient {
 public:
  explicit TestClient(uint16_t port, const char* subprotocol = kSubprotocol) {
    tcp::resolver resolver(io_);
    net::connect(ws_.next_layer(), resolver.resolve("127.0.0.1", std::to_string(port)));
    std::string proto = subprotocol;
    ws_.set_option(
        beast::websocket::stream_base::decorator([proto](beast::websocket::request_type& req) {
          if (!proto.empty()) req.set(beast::http::field::sec_websocket_protocol, proto);
        }));
    ws_.handshake("127.0.0.1", "/");
  }
  // The next message: (binary, bytes).
  std::pair<bool, std::string> next() {
    beast::flat_buffer b;
    bool done = false;
    beast::error_code error;
    ws_.async_read(b, [&](beast::error_code ec, size_t) {
      done = true;
      error = ec;
    });
    io_.restart();
    io_.run_for(std::chrono::seconds(5));
    if (!done) throw std::runtime_error("no message within 5 s");
    if (error) throw beast::system_error(error);
    return {ws_.got_binary(), beast::buffers_to_string(b.data())};
  }
  // The next text message whose op is `op` (others are skipped).
  nlohmann::json next_op(const std::string& op) {
    for (;;) {
      auto [binary, bytes] = next();
      if (binary) continue;
      auto j = nlohmann::json::parse(bytes);
      if (j["op"] == op) return j;
    }
  }
  // The next messageData message: (subscription, time, payload).
  std::tuple<uint32_t, uint64_t, std::string> next_data() {
    for (;;) {
      auto [binary, bytes] = next();
      if (binary && !bytes.empty() && static_cast<uint8_t>(bytes[0]) == kOpMessageData)
        return {read_u32_le(bytes, 1), read_u64_le(bytes, 5), bytes.substr(13)};
    }
  }
  void send_text(const std::string& text) {
    ws_.text(true);
    ws_.write(net::buffer(text));
  }
  void send_binary(const std::string& bytes) {
    ws_.binary(true);
    ws_.write(net::buffer(bytes));
  }
  void subscribe(uint32_t id, uint32_t channel) {
    send_text(nlohmann::json{{"op", "subscribe"},
                             {"subscriptions", {{{"id", id}, {"channelId", channel}}}}}
                  .dump());
  }
  beast::websocket::stream<tcp::socket>& ws() { return ws_; }

 private:
  net::io_context io_;
  beast::websocket::stream<tcp::socket> ws_{io_};
};

}  // namespace convoy::live::testing
