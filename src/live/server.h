// The live server: a Foxglove WebSocket server (`foxglove.websocket.v1`) that Foxglove,
// Lichtblick or any client of the protocol connects to while a run goes on. Channels are
// added as the run finds them; publishing puts a message into the queue of each subscribed
// client and returns (the simulation never waits for a viewer: a client's queue drops its
// oldest messages when full, and counts them). The network runs on the server's own thread.
//
// Client errors (garbage, an unknown channel, a subscription id in use) get a status message
// to that client; other clients and the run go on. Clients may publish on the topics the
// owner accepts (accept_client_topic: capability clientPublish): they advertise a channel
// with such a topic, then send its messages. A plain HTTP request on the same port gets the
// answer of ServerOptions::http (live/static_files.h: the dashboard), by default a page
// saying where to connect.
#pragma once

#include <boost/asio/io_context.hpp>
#include <condition_variable>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "live/address.h"
#include "live/channel_table.h"
#include "live/connection.h"
#include "live/protocol.h"
#include "live/send_queue.h"

namespace convoy::live {

struct ServerOptions {
  ListenAddress address;
  bool insecure = false;  // listen beyond the loopback
  ServerInfo info;
  QueueLimits limits;
  // How errors name the address ("--live 127.0.0.1:8765: cannot listen there ...") and what
  // they suggest instead of a port in use.
  std::string option = "--live";
  std::string another_port = "--live 127.0.0.1:8766";
  // Answers plain HTTP requests; default: a page naming the WebSocket URL.
  std::function<HttpAnswer(const HttpRequest&)> http;
};

// One client, while connected and after.
struct ClientStats {
  ClientId id = 0;
  std::string peer;
  uint64_t queued = 0;   // data messages put into its queue
  uint64_t sent = 0;     // messages written to it (data and control)
  uint64_t dropped = 0;  // data messages dropped from its full queue
  uint64_t errors = 0;   // status errors sent to it (bad requests)
  bool connected = false;
};

class LiveServer final : private ConnectionHost {
 public:
  // Checks the address (std::invalid_argument: not loopback without `insecure`), binds it
  // (std::runtime_error: port in use, not an address of this machine) and starts serving.
  // Both messages name --live and the address.
  explicit LiveServer(ServerOptions options);
  ~LiveServer() override;
  LiveServer(const LiveServer&) = delete;
  LiveServer& operator=(const LiveServer&) = delete;

  // "ws://HOST:PORT" with the port bound.
  std::string url() const;
  uint16_t port() const { return port_; }

  // Adds a channel and advertises it to every client; its id. Keeps the last `latch`
  // messages for new subscribers.
  uint32_t add_channel(ChannelInfo info, size_t latch = 0);
  bool has_subscribers(uint32_t channel) const;
  // To every subscriber of `channel` (and to its latch).
  void publish(uint32_t channel, uint64_t time_ns, std::shared_ptr<const std::string> payload);
  // The simulation's time, to every client (binary `time`), when it has advanced.
  void publish_time(uint64_t time_ns);

  // Clients may advertise channels on `topic` with `encoding` and publish on them: `handler`
  // gets each message's payload (on the server's thread, without the server's lock: it may
  // publish) and returns "" or an error for a status message to that client. Before clients
  // connect; ServerOptions::info should name the capability "clientPublish".
  using ClientMessageHandler = std::function<std::string(std::string_view payload)>;
  void accept_client_topic(const std::string& topic, const std::string& encoding,
                           ClientMessageHandler handler);

  // Closes every connection once its queue is sent (at most `drain_s`), then stops.
  void stop(double drain_s = 1.0);
  std::vector<ClientStats> stats() const;

 private:
  ClientId on_open(std::shared_ptr<WsConnection> connection) override;
  void on_text(ClientId client, std::string_view text) override;
  void on_binary(ClientId client, std::string_view bytes) override;
  void on_close(ClientId client, const std::string& why) override;
  HttpAnswer on_http(const HttpRequest& request) override;

  struct Client {
    std::shared_ptr<WsConnection> connection;
    ClientStats stats;
    std::map<uint32_t, ClientChannel> channels;  // advertised by the client
  };
  struct AcceptedTopic {
    std::string encoding;
    ClientMessageHandler handler;
  };
  // Under mutex_.
  void send_status(Client& c, StatusLevel level, const std::string& message);
  void subscribe(Client& c, const Subscription& s);
  void advertise(Client& c, const ClientChannel& channel);
  std::string accepted_topics() const;
  ClientStats snapshot(const Client& c) const;

  ServerOptions options_;
  boost::asio::io_context io_;
  std::shared_ptr<Listener> listener_;
  std::thread thread_;
  uint16_t port_ = 0;
  mutable std::mutex mutex_;
  std::condition_variable closed_;
  ChannelTable table_;
  std::map<std::string, AcceptedTopic> accepted_;
  std::map<ClientId, Client> clients_;
  std::vector<ClientStats> gone_;
  ClientId next_client_ = 1;
  uint64_t last_time_ns_ = 0;
  bool has_time_ = false;
  bool stopped_ = false;
};

}  // namespace convoy::live
