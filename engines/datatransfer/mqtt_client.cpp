#include "mqtt_client.h"

#include <mosquitto.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <stdexcept>

namespace convoy::datatransfer {

namespace {

constexpr int kQos = 1;
constexpr int kKeepAliveS = 60;

struct LibInit {
  LibInit() { mosquitto_lib_init(); }
  ~LibInit() { mosquitto_lib_cleanup(); }
};

std::string mosq_error(int rc) {
  if (rc == MOSQ_ERR_ERRNO) return std::strerror(errno);
  return mosquitto_strerror(rc);
}

}  // namespace

BrokerAddress parse_broker_address(const std::string& text) {
  std::string rest = text;
  if (size_t scheme = rest.find("://"); scheme != std::string::npos) {
    const std::string name = rest.substr(0, scheme);
    if (name != "tcp" && name != "mqtt") {
      throw std::invalid_argument("scheme " + name +
                                  ":// is not supported (tcp:// or mqtt://, or none)");
    }
    rest = rest.substr(scheme + 3);
  }
  BrokerAddress address;
  // [v6::addr]:port, host:port or host.
  size_t colon = std::string::npos;
  if (!rest.empty() && rest.front() == '[') {
    const size_t close = rest.find(']');
    if (close == std::string::npos) throw std::invalid_argument("unclosed '[' in the host");
    address.host = rest.substr(1, close - 1);
    if (close + 1 < rest.size()) {
      if (rest[close + 1] != ':') throw std::invalid_argument("expected ':' after ']'");
      colon = close + 1;
    }
  } else {
    colon = rest.rfind(':');
    address.host = rest.substr(0, colon);
  }
  if (colon != std::string::npos) {
    const std::string port = rest.substr(colon + 1);
    size_t used = 0;
    int value = -1;
    try {
      value = std::stoi(port, &used);
    } catch (const std::exception&) {
    }
    if (port.empty() || used != port.size() || value < 1 || value > 65535) {
      throw std::invalid_argument("port must be a number from 1 to 65535, got \"" + port + "\"");
    }
    address.port = value;
  }
  if (address.host.empty()) throw std::invalid_argument("no host name");
  return address;
}

std::string topic_problem(const std::string& topic) {
  if (topic.empty()) return "an MQTT topic must not be empty";
  if (topic.find_first_of("+#") != std::string::npos)
    return "an MQTT topic must not contain the wildcards '+' or '#'";
  if (topic.find('\0') != std::string::npos) return "an MQTT topic must not contain NUL";
  if (mosquitto_validate_utf8(topic.data(), static_cast<int>(topic.size())) != MOSQ_ERR_SUCCESS)
    return "an MQTT topic must be UTF-8";
  if (topic.size() > 65535) return "an MQTT topic must be at most 65535 bytes long";
  return "";
}

MqttClient::MqttClient() { static LibInit init; }

MqttClient::~MqttClient() {
  close(std::chrono::milliseconds(0));
  if (mosq_) mosquitto_destroy(mosq_);
}

std::string MqttClient::connect(const BrokerAddress& broker, const std::string& client_id,
                                std::chrono::milliseconds timeout) {
  mosq_ = mosquitto_new(client_id.c_str(), /*clean_session=*/true, this);
  if (!mosq_) return std::string("cannot create an MQTT client: ") + std::strerror(errno);
  mosquitto_int_option(mosq_, MOSQ_OPT_PROTOCOL_VERSION, MQTT_PROTOCOL_V311);
  mosquitto_connect_callback_set(mosq_, &MqttClient::on_connect);
  mosquitto_disconnect_callback_set(mosq_, &MqttClient::on_disconnect);
  mosquitto_publish_callback_set(mosq_, &MqttClient::on_publish);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    state_ = State::kConnecting;
  }
  // Connecting from this thread reports what fails at once (nothing listens, an unknown host);
  // the answer of the broker comes to the network thread.
  int rc = mosquitto_connect_async(mosq_, broker.host.c_str(), broker.port, kKeepAliveS);
  if (rc != MOSQ_ERR_SUCCESS) {
    std::lock_guard<std::mutex> lock(mutex_);
    state_ = State::kFailed;
    return rc == MOSQ_ERR_EAI ? "cannot resolve the host name" : mosq_error(rc);
  }
  rc = mosquitto_loop_start(mosq_);
  if (rc != MOSQ_ERR_SUCCESS) {
    std::lock_guard<std::mutex> lock(mutex_);
    state_ = State::kFailed;
    return "cannot start the MQTT network thread: " + mosq_error(rc);
  }
  loop_running_ = true;
  std::unique_lock<std::mutex> lock(mutex_);
  if (!changed_.wait_for(lock, timeout, [&] { return state_ != State::kConnecting; })) {
    state_ = State::kFailed;
    char seconds[32];
    std::snprintf(seconds, sizeof seconds, "%g", static_cast<double>(timeout.count()) / 1000.0);
    failure_ = std::string("no answer within ") + seconds + " s";
  }
  if (state_ == State::kConnected) return "";
  const std::string why = failure_;
  lock.unlock();
  // Stop trying (the network thread would reconnect forever).
  mosquitto_disconnect(mosq_);
  mosquitto_loop_stop(mosq_, /*force=*/true);
  loop_running_ = false;
  return why;
}

bool MqttClient::connected() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return state_ == State::kConnected;
}

std::string MqttClient::publish(const std::string& topic, std::string_view payload, bool retained) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (state_ != State::kConnected) return "not connected";
  }
  int mid = 0;
  const int rc = mosquitto_publish(mosq_, &mid, topic.c_str(), static_cast<int>(payload.size()),
                                   payload.data(), kQos, retained);
  if (rc == MOSQ_ERR_SUCCESS) {
    std::lock_guard<std::mutex> lock(mutex_);
    ++published_;
    return "";
  }
  return mosq_error(rc);
}

std::string MqttClient::take_lost_connection() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (lost_.empty() || lost_reported_) return "";
  lost_reported_ = true;
  return lost_;
}

uint64_t MqttClient::close(std::chrono::milliseconds timeout) {
  std::unique_lock<std::mutex> lock(mutex_);
  if (state_ != State::kConnected) {
    state_ = State::kClosed;
    return 0;
  }
  changed_.wait_for(lock, timeout, [&] { return acknowledged_ >= published_; });
  const uint64_t left = published_ - std::min(acknowledged_, published_);
  state_ = State::kClosed;
  lock.unlock();
  mosquitto_disconnect(mosq_);
  if (loop_running_) {
    // Once disconnected, the network thread ends by itself; a broker that stopped answering
    // cannot hold it up.
    mosquitto_loop_stop(mosq_, /*force=*/left > 0);
    loop_running_ = false;
  }
  return left;
}

void MqttClient::on_connect(mosquitto*, void* self, int rc) {
  auto* c = static_cast<MqttClient*>(self);
  std::lock_guard<std::mutex> lock(c->mutex_);
  if (c->state_ == State::kConnecting) {
    if (rc == 0) {
      c->state_ = State::kConnected;
    } else {
      c->state_ = State::kFailed;
      c->failure_ = std::string("refused by the broker: ") + mosquitto_connack_string(rc);
    }
  } else if (c->state_ == State::kConnected && rc == 0 && !c->lost_.empty()) {
    // Reconnected by the network thread.
    c->lost_.clear();
    c->lost_reported_ = false;
  }
  c->changed_.notify_all();
}

void MqttClient::on_disconnect(mosquitto*, void* self, int rc) {
  auto* c = static_cast<MqttClient*>(self);
  std::lock_guard<std::mutex> lock(c->mutex_);
  if (c->state_ == State::kConnecting) {
    c->state_ = State::kFailed;
    c->failure_ = rc == MOSQ_ERR_CONN_LOST ? "connection closed" : mosquitto_strerror(rc);
  } else if (c->state_ == State::kConnected && rc != 0 && c->lost_.empty()) {
    c->lost_ = mosquitto_strerror(rc);
  }
  c->changed_.notify_all();
}

void MqttClient::on_publish(mosquitto*, void* self, int) {
  auto* c = static_cast<MqttClient*>(self);
  std::lock_guard<std::mutex> lock(c->mutex_);
  ++c->acknowledged_;
  c->changed_.notify_all();
}

}  // namespace convoy::datatransfer
