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

tcp::endpoint resolve(net::io_context& io, const ListenAddress& address, bool insecure,
                      const std::string& option) {
  boost::system::error_code ec;
  tcp::resolver resolver(io);
  auto results = resolver.resolve(address.host, std::to_string(address.port),
                                  tcp::resolver::numeric_service | tcp::resolver::passive, ec);
  if (ec || results.empty())
    throw std::runtime_error(option + " " + address.text() + ": cannot resolve the host '" +
                             address.host + "': " + ec.message());
  const tcp::endpoint endpoint = *results.begin();
  if (!insecure && !endpoint.address().is_loopback()) {
    ListenAddress resolved = address;
    resolved.host = endpoint.address().to_string();
    check_listen_policy(resolved, insecure);  // throws, naming the resolved address
  }
  return endpoint;
}

// A client's text quoted in a status message: at most 100 bytes of it.
std::string clip(const std::string& text) {
  return text.size() <= 100 ? text : text.substr(0, 100) + "...";
}

}  // namespace

LiveServer::LiveServer(ServerOptions options) : options_(std::move(options)) {
  check_listen_policy(options_.address, options_.insecure);
  const tcp::endpoint endpoint = resolve(io_, options_.address, options_.insecure, options_.option);
  try {
    ConnectionHost& host = *this;
    listener_ = std::make_shared<Listener>(io_, endpoint, host, options_.limits);
  } catch (const boost::system::system_error& e) {
    throw std::runtime_error(options_.option + " " + options_.address.text() +
                             ": cannot listen there (" + e.code().message() +
                             "): give another port, e.g. " + options_.another_port);
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
    case ClientRequest::Op::kAdvertise:
      for (const auto& ch : request.advertise) advertise(c, ch);
      break;
    case ClientRequest::Op::kUnadvertise:
      for (uint32_t id : request.unadvertise) {
        if (c.channels.erase(id) == 0)
          send_status(c, StatusLevel::kError,
                      "unadvertise: no client channel " + std::to_string(id) + " was advertised");
      }
      break;
    case ClientRequest::Op::kUnsupported:
      send_status(c, StatusLevel::kError,
                  "unsupported operation \"" + clip(request.error) +
                      "\" (this server supports subscribe, unsubscribe" +
                      (accepted_.empty() ? "" : ", advertise and unadvertise") + ")");
      break;
    case ClientRequest::Op::kInvalid:
      send_status(c, StatusLevel::kError, "invalid message: " + request.error);
      break;
  }
}

void LiveServer::accept_client_topic(const std::string& topic, const std::string& encoding,
                                     ClientMessageHandler handler) {
  std::lock_guard<std::mutex> lock(mutex_);
  accepted_[topic] = {encoding, std::move(handler)};
}

std::string LiveServer::accepted_topics() const {
  std::string list;
  for (const auto& [topic, a] : accepted_)
    list += (list.empty() ? "" : ", ") + topic + " (" + a.encoding + ")";
  return list;
}

void LiveServer::advertise(Client& c, const ClientChannel& ch) {
  if (accepted_.empty())
    return send_status(c, StatusLevel::kError,
                       "advertise: this server does not accept client publishing");
  auto it = accepted_.find(ch.topic);
  if (it == accepted_.end())
    return send_status(c, StatusLevel::kError,
                       "advertise: clients cannot publish on \"" + clip(ch.topic) +
                           "\" (this server accepts: " + accepted_topics() + ")");
  if (ch.encoding != it->second.encoding)
    return send_status(c, StatusLevel::kError,
                       "advertise: \"" + ch.topic + "\" takes the encoding \"" +
                           it->second.encoding + "\", not \"" + clip(ch.encoding) + "\"");
  if (c.channels.count(ch.id))
    return send_status(c, StatusLevel::kError,
                       "advertise: client channel id " + std::to_string(ch.id) +
                           " is in use (unadvertise it first)");
  c.channels[ch.id] = ch;
}

void LiveServer::on_binary(ClientId client, std::string_view bytes) {
  ClientMessageHandler handler;
  std::string error;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    auto it = clients_.find(client);
    if (it == clients_.end()) return;
    Client& c = it->second;
    const ClientData data = parse_client_binary(bytes);
    if (!data.error.empty()) return send_status(c, StatusLevel::kError, data.error);
    if (accepted_.empty())
      return send_status(c, StatusLevel::kError,
                         "binary message of " + std::to_string(bytes.size()) +
                             " bytes ignored: this server does not accept client publishing");
    auto ch = c.channels.find(data.channel_id);
    if (ch == c.channels.end())
      return send_status(c, StatusLevel::kError,
                         "message on client channel " + std::to_string(data.channel_id) +
                             ", which was not advertised (advertise it first)");
    auto topic = accepted_.find(ch->second.topic);
    if (topic == accepted_.end()) return;
    handler = topic->second.handler;
    bytes = data.payload;
  }
  try {
    error = handler ? handler(bytes) : std::string();
  } catch (const std::exception& e) {
    error = e.what();
  }
  if (error.empty()) return;
  std::lock_guard<std::mutex> lock(mutex_);
  auto it = clients_.find(client);
  if (it != clients_.end()) send_status(it->second, StatusLevel::kError, error);
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

HttpAnswer LiveServer::on_http(const HttpRequest& request) {
  if (options_.http) return options_.http(request);
  if (request.method != "GET" && request.method != "HEAD")
    return HttpAnswer::text(405, "GET only\n");
  if (request.target != "/") return HttpAnswer::text(404, "not found\n");
  return HttpAnswer::text(200, options_.info.name + ": a Foxglove WebSocket server (" +
                                   kSubprotocol + "). Open " + url() +
                                   " in Foxglove or Lichtblick (Open connection -> "
                                   "Foxglove WebSocket).\n");
}

}  // namespace convoy::live
