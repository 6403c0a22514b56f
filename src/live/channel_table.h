// The live server's channels and who is subscribed to them: the bookkeeping of the protocol,
// apart from the transport. Not thread-safe: the server (live/server.h) holds it under its
// lock.
//
// A channel may be latched: it keeps its last N messages and a new subscriber gets them first
// (the log, so that a viewer that connects late sees how the run started; a camera's
// calibration).
#pragma once

#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "live/protocol.h"

namespace convoy::live {

using ClientId = uint64_t;

struct Subscriber {
  ClientId client = 0;
  uint32_t subscription = 0;
};

struct Latched {
  uint64_t time_ns = 0;
  std::shared_ptr<const std::string> payload;
};

class ChannelTable {
 public:
  // Adds a channel (its id is given here: 1, 2, ...); keeps its last `latch` messages.
  uint32_t add(ChannelInfo info, size_t latch = 0);
  const ChannelInfo* find(uint32_t id) const;
  std::vector<ChannelInfo> all() const;

  // "" when done; otherwise why not (unknown channel, subscription id in use, already
  // subscribed to that channel), and nothing changes.
  std::string subscribe(ClientId client, const Subscription& s);
  std::string unsubscribe(ClientId client, uint32_t subscription);
  void remove_client(ClientId client);

  bool has_subscribers(uint32_t channel) const;
  const std::vector<Subscriber>& subscribers(uint32_t channel) const;
  size_t subscription_count(ClientId client) const;

  // Keeps a message of a latched channel (no-op for others).
  void latch(uint32_t channel, uint64_t time_ns, std::shared_ptr<const std::string> payload);
  const std::deque<Latched>& latched(uint32_t channel) const;

 private:
  struct Channel {
    ChannelInfo info;
    size_t latch = 0;
    std::deque<Latched> kept;
    std::vector<Subscriber> subscribers;
  };
  Channel* get(uint32_t id);
  const Channel* get(uint32_t id) const;

  std::vector<Channel> channels_;  // id - 1
  // client -> subscription id -> channel id
  std::map<ClientId, std::map<uint32_t, uint32_t>> subscriptions_;
};

}  // namespace convoy::live
