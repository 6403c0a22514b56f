#include "live/connection.h"

#include <array>
#include <boost/asio/post.hpp>
#include <boost/asio/strand.hpp>
#include <boost/beast/core/string.hpp>
#include <chrono>

#include "live/protocol.h"

namespace convoy::live {

namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
namespace net = boost::asio;
using tcp = net::ip::tcp;

namespace {

constexpr size_t kMaxClientMessage = 1 << 20;  // a subscribe to thousands of channels fits
constexpr auto kRequestTimeout = std::chrono::seconds(10);

// True when the comma-separated header `offered` names `protocol`.
bool offers(beast::string_view offered, beast::string_view protocol) {
  for (auto token : http::token_list(offered))
    if (beast::iequals(token, protocol)) return true;
  return false;
}

std::string peer_of(const tcp::socket& socket) {
  boost::system::error_code ec;
  const auto ep = socket.remote_endpoint(ec);
  return ec ? "?" : ep.address().to_string() + ":" + std::to_string(ep.port());
}

// The first request on a connection: an upgrade becomes a WsConnection; anything else gets
// the host's HTTP answer and the connection closes.
class HttpConnection : public std::enable_shared_from_this<HttpConnection> {
 public:
  HttpConnection(tcp::socket socket, ConnectionHost& host, QueueLimits limits)
      : stream_(std::move(socket)), host_(host), limits_(limits) {}

  void start() {
    parser_.emplace();
    parser_->header_limit(16 * 1024);
    parser_->body_limit(64 * 1024);
    stream_.expires_after(kRequestTimeout);
    http::async_read(stream_, buffer_, *parser_,
                     [self = shared_from_this()](beast::error_code ec, size_t) {
                       if (!ec) self->on_request();
                     });
  }

 private:
  void on_request() {
    auto request = parser_->release();
    if (websocket::is_upgrade(request)) {
      if (!offers(request[http::field::sec_websocket_protocol], kSubprotocol)) {
        answer(request, {400, "text/plain; charset=utf-8",
                         std::string("this server speaks the WebSocket subprotocol ") +
                             kSubprotocol + " only\n"});
        return;
      }
      stream_.expires_never();
      auto ws = std::make_shared<WsConnection>(stream_.release_socket(), host_, limits_);
      ws->start(std::move(request));
      return;
    }
    answer(request,
           host_.on_http(std::string(request.method_string()), std::string(request.target())));
  }

  void answer(const http::request<http::string_body>& request, HttpAnswer a) {
    auto res = std::make_shared<http::response<http::string_body>>(
        static_cast<http::status>(a.status), request.version());
    res->set(http::field::server, "convoy-live");
    res->set(http::field::content_type, a.content_type);
    res->keep_alive(false);
    if (request.method() != http::verb::head) res->body() = std::move(a.body);
    res->prepare_payload();
    http::async_write(stream_, *res, [self = shared_from_this(), res](beast::error_code, size_t) {
      beast::error_code ignored;
      self->stream_.socket().shutdown(tcp::socket::shutdown_send, ignored);
    });
  }

  beast::tcp_stream stream_;
  beast::flat_buffer buffer_;
  std::optional<http::request_parser<http::string_body>> parser_;
  ConnectionHost& host_;
  QueueLimits limits_;
};

}  // namespace

WsConnection::WsConnection(tcp::socket socket, ConnectionHost& host, QueueLimits limits)
    : ws_(std::move(socket)), host_(host), queue_(limits) {
  peer_ = peer_of(beast::get_lowest_layer(ws_).socket());
}

void WsConnection::start(http::request<http::string_body> request) {
  ws_.set_option(websocket::stream_base::timeout::suggested(beast::role_type::server));
  ws_.set_option(websocket::stream_base::decorator([](websocket::response_type& res) {
    res.set(http::field::server, "convoy-live");
    res.set(http::field::sec_websocket_protocol, kSubprotocol);
  }));
  ws_.read_message_max(kMaxClientMessage);
  ws_.async_accept(request, [self = shared_from_this()](beast::error_code ec) {
    if (ec) return;  // not a client yet: nothing to tell the host
    self->open_ = true;
    self->id_ = self->host_.on_open(self);
    self->read();
    self->write_next();
  });
}

void WsConnection::read() {
  ws_.async_read(in_, [self = shared_from_this()](beast::error_code ec, size_t bytes) {
    if (ec) return self->finish(ec.message());
    const auto data = self->in_.cdata();
    if (self->ws_.got_text())
      self->host_.on_text(self->id_,
                          std::string_view(static_cast<const char*>(data.data()), data.size()));
    else
      self->host_.on_binary(self->id_, bytes);
    self->in_.consume(self->in_.size());
    self->read();
  });
}

void WsConnection::kick() {
  if (kick_pending_.exchange(true)) return;
  net::post(ws_.get_executor(), [self = shared_from_this()] {
    self->kick_pending_ = false;
    self->write_next();
  });
}

void WsConnection::close() {
  net::post(ws_.get_executor(), [self = shared_from_this()] {
    self->closing_ = true;
    self->write_next();
  });
}

void WsConnection::write_next() {
  if (!open_ || writing_ || finished_) return;
  current_ = queue_.pop();
  if (!current_) {
    if (closing_) {
      finished_ = true;
      ws_.async_close(websocket::close_code::going_away,
                      [self = shared_from_this()](beast::error_code) {
                        self->host_.on_close(self->id_, "closed by the server");
                      });
    }
    return;
  }
  writing_ = true;
  ws_.binary(current_->binary);
  static const std::string kEmpty;
  std::array<net::const_buffer, 2> buffers{net::buffer(current_->head),
                                           net::buffer(current_->body ? *current_->body : kEmpty)};
  ws_.async_write(buffers, [self = shared_from_this()](beast::error_code ec, size_t) {
    self->writing_ = false;
    self->current_.reset();
    if (ec) return self->finish(ec.message());
    self->sent_.fetch_add(1, std::memory_order_relaxed);
    self->write_next();
  });
}

void WsConnection::finish(const std::string& why) {
  if (finished_) return;
  finished_ = true;
  beast::error_code ignored;
  beast::get_lowest_layer(ws_).socket().close(ignored);
  host_.on_close(id_, why);
}

Listener::Listener(net::io_context& io, const tcp::endpoint& endpoint, ConnectionHost& host,
                   QueueLimits limits)
    : io_(io), acceptor_(io), host_(host), limits_(limits) {
  acceptor_.open(endpoint.protocol());
  acceptor_.set_option(net::socket_base::reuse_address(true));
  acceptor_.bind(endpoint);
  acceptor_.listen(net::socket_base::max_listen_connections);
}

void Listener::start() { accept(); }

void Listener::stop() {
  beast::error_code ignored;
  acceptor_.close(ignored);
}

void Listener::accept() {
  acceptor_.async_accept(
      net::make_strand(io_), [self = shared_from_this()](beast::error_code ec, tcp::socket socket) {
        if (ec == net::error::operation_aborted) return;
        if (!ec)
          std::make_shared<HttpConnection>(std::move(socket), self->host_, self->limits_)->start();
        self->accept();
      });
}

}  // namespace convoy::live
