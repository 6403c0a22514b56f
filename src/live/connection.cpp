#include "live/connection.h"

#include <array>
#include <boost/asio/post.hpp>
#include <boost/asio/strand.hpp>
#include <boost/beast/core/file.hpp>
#include <boost/beast/core/string.hpp>
#include <boost/beast/http/basic_file_body.hpp>
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
constexpr auto kWriteTimeout = std::chrono::minutes(30);

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

// A part of a file, as a Beast File (http::basic_file_body sends all of its file).
class FileRange {
 public:
  bool is_open() const { return file_.is_open(); }
  void close(beast::error_code& ec) { file_.close(ec); }
  void open(const char* path, beast::file_mode mode, beast::error_code& ec) {
    file_.open(path, mode, ec);
  }
  // Opens `path` for reading from `offset`, `length` bytes.
  void open_range(const std::string& path, uint64_t offset, uint64_t length,
                  beast::error_code& ec) {
    file_.open(path.c_str(), beast::file_mode::scan, ec);
    if (!ec) file_.seek(offset, ec);
    offset_ = offset;
    length_ = length;
  }
  uint64_t size(beast::error_code& ec) const {
    ec = {};
    return length_;
  }
  uint64_t pos(beast::error_code& ec) const { return file_.pos(ec) - offset_; }
  void seek(uint64_t offset, beast::error_code& ec) { file_.seek(offset_ + offset, ec); }
  size_t read(void* buffer, size_t n, beast::error_code& ec) const {
    return file_.read(buffer, n, ec);
  }
  size_t write(const void*, size_t, beast::error_code& ec) {
    ec = beast::errc::make_error_code(beast::errc::operation_not_permitted);
    return 0;
  }

 private:
  beast::file file_;
  uint64_t offset_ = 0, length_ = 0;
};
using FileRangeBody = http::basic_file_body<FileRange>;

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
        answer(request,
               HttpAnswer::text(400, std::string("this server speaks the WebSocket subprotocol ") +
                                         kSubprotocol + " only\n"));
        return;
      }
      stream_.expires_never();
      auto ws = std::make_shared<WsConnection>(stream_.release_socket(), host_, limits_);
      ws->start(std::move(request));
      return;
    }
    HttpRequest r{std::string(request.method_string()), std::string(request.target()),
                  std::string(request[http::field::range])};
    answer(request, host_.on_http(r));
  }

  void answer(const http::request<http::string_body>& request, HttpAnswer a) {
    const bool head = request.method() == http::verb::head;
    auto header = [&](auto& res) {
      res.set(http::field::server, "convoy-live");
      res.set(http::field::content_type, a.content_type);
      for (const auto& [name, value] : a.headers) res.set(name, value);
      res.keep_alive(false);
    };
    if (!a.file.empty() && !head) {
      auto res = std::make_shared<http::response<FileRangeBody>>(
          static_cast<http::status>(a.status), request.version());
      beast::error_code ec;
      FileRange range;
      range.open_range(a.file, a.file_offset, a.file_length, ec);
      if (!ec) res->body().reset(std::move(range), ec);
      if (ec) {
        answer(request, HttpAnswer::text(500, "cannot read the file\n"));
        return;
      }
      header(*res);
      res->content_length(a.file_length);
      send(res);
      return;
    }
    if (head) {
      auto res = std::make_shared<http::response<http::empty_body>>(
          static_cast<http::status>(a.status), request.version());
      header(*res);
      res->content_length(a.file.empty() ? a.body.size() : a.file_length);
      send(res);
      return;
    }
    auto res = std::make_shared<http::response<http::string_body>>(
        static_cast<http::status>(a.status), request.version());
    header(*res);
    res->body() = std::move(a.body);
    res->prepare_payload();
    send(res);
  }

  template <typename Response>
  void send(std::shared_ptr<Response> res) {
    stream_.expires_after(kWriteTimeout);  // a recording of a few GB to a slow viewer
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
  ws_.async_read(in_, [self = shared_from_this()](beast::error_code ec, size_t) {
    if (ec) return self->finish(ec.message());
    const auto data = self->in_.cdata();
    if (self->ws_.got_text())
      self->host_.on_text(self->id_,
                          std::string_view(static_cast<const char*>(data.data()), data.size()));
    else
      self->host_.on_binary(self->id_,
                            std::string_view(static_cast<const char*>(data.data()), data.size()));
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
