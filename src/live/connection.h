// The live server's transport (Boost.Beast): the listener, a first HTTP request on each
// connection (a WebSocket upgrade asking for `foxglove.websocket.v1`, or a plain HTTP GET, so
// that a web page can be served from the same port), and WebSocket connections that send what
// their SendQueue holds. All of it runs on the server's one I/O thread; other threads only
// push to a connection's queue and kick() it. What the messages mean is the server's
// (live/server.h), through ConnectionHost.
#pragma once

#include <atomic>
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "live/channel_table.h"
#include "live/send_queue.h"

namespace convoy::live {

class WsConnection;

// A plain HTTP request, as the host sees it.
struct HttpRequest {
  std::string method;  // "GET", "HEAD", ...
  std::string target;  // "/index.html?x=1" (as sent: percent-encoded, with the query)
  std::string range;   // the Range header, or ""
};

// The host's answer: `body`, or `file_length` bytes of the file `file` from `file_offset`
// (sent from the disk as it goes: a recording may be large).
struct HttpAnswer {
  unsigned status = 404;
  std::string content_type = "text/plain; charset=utf-8";
  std::string body;
  std::string file;
  uint64_t file_offset = 0, file_length = 0;
  std::vector<std::pair<std::string, std::string>> headers;  // more: Content-Range, ...

  static HttpAnswer text(unsigned status, std::string body,
                         std::string content_type = "text/plain; charset=utf-8") {
    HttpAnswer a;
    a.status = status;
    a.content_type = std::move(content_type);
    a.body = std::move(body);
    return a;
  }
};

// What the server does with connections (called on the I/O thread).
class ConnectionHost {
 public:
  virtual ~ConnectionHost() = default;
  // A WebSocket client is connected: its id (its serverInfo and advertise are queued).
  virtual ClientId on_open(std::shared_ptr<WsConnection> connection) = 0;
  virtual void on_text(ClientId client, std::string_view text) = 0;
  virtual void on_binary(ClientId client, std::string_view bytes) = 0;
  virtual void on_close(ClientId client, const std::string& why) = 0;
  // A plain HTTP request (not an upgrade).
  virtual HttpAnswer on_http(const HttpRequest& request) = 0;
};

class WsConnection : public std::enable_shared_from_this<WsConnection> {
 public:
  WsConnection(boost::asio::ip::tcp::socket socket, ConnectionHost& host, QueueLimits limits);
  // Completes the handshake of `request` (an upgrade), then reads and writes.
  void start(boost::beast::http::request<boost::beast::http::string_body> request);
  // Any thread: something was queued.
  void kick();
  // Any thread: close once the queue is sent.
  void close();
  SendQueue& queue() { return queue_; }
  const std::string& peer() const { return peer_; }
  uint64_t sent() const { return sent_.load(); }

 private:
  void read();
  void write_next();
  void finish(const std::string& why);

  boost::beast::websocket::stream<boost::beast::tcp_stream> ws_;
  ConnectionHost& host_;
  SendQueue queue_;
  std::string peer_;
  boost::beast::flat_buffer in_;
  std::optional<OutMessage> current_;
  ClientId id_ = 0;
  bool open_ = false, writing_ = false, closing_ = false, finished_ = false;
  std::atomic<bool> kick_pending_{false};
  std::atomic<uint64_t> sent_{0};
};

// Accepts connections and reads each one's first request.
class Listener : public std::enable_shared_from_this<Listener> {
 public:
  // Binds and listens at `endpoint`; throws boost::system::system_error.
  Listener(boost::asio::io_context& io, const boost::asio::ip::tcp::endpoint& endpoint,
           ConnectionHost& host, QueueLimits limits);
  void start();
  void stop();  // on the I/O thread
  boost::asio::ip::tcp::endpoint local_endpoint() const { return acceptor_.local_endpoint(); }

 private:
  void accept();
  boost::asio::io_context& io_;
  boost::asio::ip::tcp::acceptor acceptor_;
  ConnectionHost& host_;
  QueueLimits limits_;
};

}  // namespace convoy::live
