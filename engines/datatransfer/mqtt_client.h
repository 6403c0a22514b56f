// A publishing MQTT client on libmosquitto (MQTT 3.1.1, QoS 1, as NRP-Core's client), that never
// blocks the simulation: the network is libmosquitto's own thread (mosquitto_loop_start), and
// publish() only queues. Only connect() and close() wait, each for a bounded time.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <string>
#include <string_view>

struct mosquitto;

namespace convoy::datatransfer {

// "host:port", "tcp://host:port" or "mqtt://host" (port 1883). Throws std::invalid_argument
// explaining what is wrong (another scheme, a bad port).
struct BrokerAddress {
  std::string host;
  int port = 1883;
};
BrokerAddress parse_broker_address(const std::string& text);

// Why `topic` cannot be published to ("" if it can): empty, wildcards '+' or '#', not UTF-8,
// longer than 65535 bytes.
std::string topic_problem(const std::string& topic);

class MqttClient {
 public:
  MqttClient();
  ~MqttClient();
  MqttClient(const MqttClient&) = delete;
  MqttClient& operator=(const MqttClient&) = delete;

  // Connects as `client_id` and waits up to `timeout` for the broker's CONNACK. Returns "" once
  // connected, else why not (nothing listens, refused by the broker, no answer in time); the
  // client then stays unconnected and publish() does nothing.
  std::string connect(const BrokerAddress& broker, const std::string& client_id,
                      std::chrono::milliseconds timeout);
  bool connected() const;

  // Queues a QoS 1 message. Returns "" when queued, else why not (not connected, payload too
  // large...). Never waits for the network.
  std::string publish(const std::string& topic, std::string_view payload, bool retained);

  // "" while the connection holds; the reason once, after it was lost (libmosquitto's thread
  // then tries to reconnect; messages published meanwhile are queued by libmosquitto).
  std::string take_lost_connection();

  // Waits up to `timeout` until the broker acknowledged every message, then disconnects.
  // Returns the number of messages left unacknowledged.
  uint64_t close(std::chrono::milliseconds timeout);

 private:
  static void on_connect(mosquitto*, void* self, int rc);
  static void on_disconnect(mosquitto*, void* self, int rc);
  static void on_publish(mosquitto*, void* self, int mid);

  mosquitto* mosq_ = nullptr;
  bool loop_running_ = false;
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  enum class State { kIdle, kConnecting, kConnected, kFailed, kClosed } state_ = State::kIdle;
  std::string failure_;
  std::string lost_;
  bool lost_reported_ = false;
  uint64_t published_ = 0;
  uint64_t acknowledged_ = 0;
};

}  // namespace convoy::datatransfer
