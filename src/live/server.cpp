#include "live/server.h"

#include <algorithm>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/post.hpp>
#include <chrono>
#include <condition_variable>
#include <stdexcept>

namespace convoy::live {

namespace net = boost::asio;
using tcp = net::ip::tcp;

namespace {

tcp::endpoint resolve(net::io_context& io, const ListenAddress& address, bool insecure) {
  boost::system::error_code ec;
  tcp::resolver resolver(io);
  auto results = resolver.resolve(address.host, std::to_string(address.port),
                                  tcp::resolver::numeric_service | tcp::resolver::passive, ec);
  if (ec || results.empty())
    throw std::runtime_error("--live " + address.text() + ": cannot resolve the host '" +
                             address.host + "': " + ec.message());
  const tcp::endpoint endpoint = *results.begin();
  if (!insecure && !endpoint.address().is_loopback()) {
    ListenAddress resolved = address;
    resolved.host = endpoint.address().to_string();
    check_listen_policy(resolved, insecure);  // throws, naming the resolved address
  }
  return endpoint;
}

}  // namespace

LiveServer::LiveServer(ServerOptions options) : options_(std::move(options)) {
  check_listen_policy(options_.address, options_.insecure);
  const tcp::endpoint endpoint = resolve(io_, options_.address, options_.insecure);
  try {
    ConnectionHost& host = *this;
    listener_ = std::make_shared<Listener>(io_, endpoint, host, options_.limits);
  } catch (const boost::system::system_error& e) {
    throw std::runtime_error("--live " + options_.address.text() + ": cannot listen there (" +
                             e.code().message() +
                             "): give another port, e.g. --live 127.0.0.1:8766");
  }
  port_ = listener_->local_endpoint().port();
  listener_->start();
  thread_ = std::thread([this] { io_.run(); });
}

LiveServer::~LiveServer() { stop(0.2); }

std::string LiveServer::url() const {
  ListenAddress a = options_.address;
  a.port = port_;
  return "ws://" + a.text();
}

uint32_t LiveServer::add_channel(ChannelInfo info, size_t latch) {
  std::lock_guard<std::mutex> lock(mutex_);
  const uint32_t id = table_.add(std::move(info), latch);
  const auto text = std::make_shared<const std::string>(advertise_json({*table_.find(id)}));
  for (auto& [cid, c] : clients_) {
    c.connection->queue().push_control({false, "", text});
    c.connection->kick();
  }
  return id;
}

bool LiveServer::has_subscribers(uint32_t channel) const {
  std::lock_guard<std::mutex> lock(mutex_);
  return table_.has_subscribers(channel);
}

void LiveServer::publish(uint32_t channel, uint64_t time_ns,
                         std::shared_ptr<const std::string> payload) {
  std::lock_guard<std::mutex> lock(mutex_);
  table_.latch(channel, time_ns, payload);
  for (const auto& s : table_.subscribers(channel)) {
    auto it = clients_.find(s.client);
    if (it == clients_.end()) continue;
    it->second.connection->queue().push_data(
        {true, message_data_header(s.subscription, time_ns), payload});
    it->second.connection->kick();
  }
}

void LiveServer::publish_time(uint64_t time_ns) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (has_time_ && time_ns <= last_time_ns_) return;
  has_time_ = true;
  last_time_ns_ = time_ns;
  if (clients_.empty()) return;
  auto body = std::make_shared<const std::string>(time_message(time_ns));
  for (auto& [cid, c] : clients_) {
    c.connection->queue().push_data({true, "", body});
    c.connection->kick();
  }
}

void LiveServer::stop(double drain_s) {
  {
    std::unique_lock<std::mutex> lock(mutex_);
    if (stopped_) return;
    stopped_ = true;
    for (auto& [id, c] : clients_) c.connection->close();
    net::post(io_, [l = listener_] { l->stop(); });
    closed_.wait_for(lock, std::chrono::duration<double>(drain_s),
                     [this] { return clients_.empty(); });
  }
  io_.stop();
  if (thread_.joinable()) thread_.join();
  std::lock_guard<std::mutex> lock(mutex_);
  for (auto& [id, c] : clients_) gone_.push_back(snapshot(c));
  clients_.clear();
}

ClientStats LiveServer::snapshot(const Client& c) const {
  ClientStats s = c.stats;
  s.queued = c.connection->queue().pushed();
  s.dropped = c.connection->queue().dropped();
  s.sent = c.connection->sent();
  return s;
}

std::vector<ClientStats> LiveServer::stats() const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<ClientStats> out = gone_;
  for (const auto& [id, c] : clients_) out.push_back(snapshot(c));
  std::sort(out.begin(), out.end(),
            [](const ClientStats& a, const ClientStats& b) { return a.id < b.id; });
  return out;
}

ClientId LiveServer::on_open(std::shared_ptr<WsConnection> connection) {
  std::lock_guard<std::mutex> lock(mutex_);
  const ClientId id = next_client_++;
  Client& c = clients_[id];
  c.connection = std::move(connection);
  c.stats.id = id;
  c.stats.peer = c.connection->peer();
  c.stats.connected = true;
  auto& q = c.connection->queue();
  q.push_control({false, "", std::make_shared<const std::string>(server_info_json(options_.info))});
  q.push_control({false, "", std::make_shared<const std::string>(advertise_json(table_.all()))});
  if (has_time_)
    q.push_control({true, "", std::make_shared<const std::string>(time_message(last_time_ns_))});
  if (stopped_) c.connection->close();
  return id;
}

void LiveServer::send_status(Client& c, StatusLevel level, const std::string& message) {
  if (level == StatusLevel::kError) ++c.stats.errors;
  c.connection->queue().push_control(
      {false, "", std::make_shared<const std::string>(status_json(level, message))});
  c.connection->kick();
}

void LiveServer::subscribe(Client& c, const Subscription& s) {
  const std::string error = table_.subscribe(c.stats.id, s);
  if (!error.empty()) return send_status(c, StatusLevel::kError, error);
  for (const auto& kept : table_.latched(s.channel_id)) {
    c.connection->queue().push_data({true, message_data_header(s.id, kept.time_ns), kept.payload});
  }
  c.connection->kick();
}

void LiveServer::on_text(ClientId client, std::string_view text) {
  std::lock_guard<std::mutex> lock(mutex_);
  auto it = clients_.find(client);
  if (it == clients_.end()) return;
  Client& c = it->second;
  const ClientRequest request = parse_client_message(text);
  switch (request.op) {
    case ClientRequest::Op::kSubscribe:
      for (const auto& s : request.subscribe) subscribe(c, s);
      break;
    case ClientRequest::Op::kUnsubscribe:
      for (uint32_t id : request.unsubscribe) {
        const std::string error = table_.unsubscribe(client, id);
        if (!error.empty()) send_status(c, StatusLevel::kError, error);
      }
      break;
    case ClientRequest::Op::kUnsupported:
      send_status(c, StatusLevel::kError,
                  "unsupported operation \"" + request.error +
                      "\" (this server supports subscribe and unsubscribe)");
      break;
    case ClientRequest::Op::kInvalid:
      send_status(c, StatusLevel::kError, "invalid message: " + request.error);
      break;
  }
}

void LiveServer::on_binary(ClientId client, size_t bytes) {
  std::lock_guard<std::mutex> lock(mutex_);
  auto it = clients_.find(client);
  if (it == clients_.end()) return;
  send_status(it->second, StatusLevel::kError,
              "binary message of " + std::to_string(bytes) +
                  " bytes ignored: this server does not accept client publishing");
}

void LiveServer::on_close(ClientId client, const std::string& why) {
  std::lock_guard<std::mutex> lock(mutex_);
  auto it = clients_.find(client);
  if (it == clients_.end()) return;
  table_.remove_client(client);
  ClientStats s = snapshot(it->second);
  s.connected = false;
  gone_.push_back(s);
  clients_.erase(it);
  closed_.notify_all();
}

HttpAnswer LiveServer::on_http(const std::string& method, const std::string& target) {
  if (options_.http) return options_.http(method, target);
  if (method != "GET" && method != "HEAD") return {405, "text/plain; charset=utf-8", "GET only\n"};
  if (target != "/") return {404, "text/plain; charset=utf-8", "not found\n"};
  return {200, "text/plain; charset=utf-8",
          options_.info.name + ": a Foxglove WebSocket server (" + kSubprotocol + "). Open " +
              url() +
              " in Foxglove or Lichtblick (Open connection -> "
              "Foxglove WebSocket).\n"};
}

}  // namespace convoy::live
