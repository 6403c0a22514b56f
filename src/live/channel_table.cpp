#include "live/channel_table.h"

#include <algorithm>

namespace convoy::live {

uint32_t ChannelTable::add(ChannelInfo info, size_t latch) {
  info.id = static_cast<uint32_t>(channels_.size() + 1);
  Channel c;
  c.info = std::move(info);
  c.latch = latch;
  channels_.push_back(std::move(c));
  return channels_.back().info.id;
}

ChannelTable::Channel* ChannelTable::get(uint32_t id) {
  return id >= 1 && id <= channels_.size() ? &channels_[id - 1] : nullptr;
}

const ChannelTable::Channel* ChannelTable::get(uint32_t id) const {
  return id >= 1 && id <= channels_.size() ? &channels_[id - 1] : nullptr;
}

const ChannelInfo* ChannelTable::find(uint32_t id) const {
  const Channel* c = get(id);
  return c ? &c->info : nullptr;
}

std::vector<ChannelInfo> ChannelTable::all() const {
  std::vector<ChannelInfo> out;
  for (const auto& c : channels_) out.push_back(c.info);
  return out;
}

std::string ChannelTable::subscribe(ClientId client, const Subscription& s) {
  Channel* c = get(s.channel_id);
  if (!c) return "subscribe: unknown channel id " + std::to_string(s.channel_id);
  auto& mine = subscriptions_[client];
  if (mine.count(s.id))
    return "subscribe: subscription id " + std::to_string(s.id) + " is already in use";
  for (const auto& [sub, channel] : mine) {
    if (channel == s.channel_id)
      return "subscribe: already subscribed to channel " + std::to_string(s.channel_id) +
             " (subscription " + std::to_string(sub) + ")";
  }
  mine[s.id] = s.channel_id;
  c->subscribers.push_back({client, s.id});
  return "";
}

std::string ChannelTable::unsubscribe(ClientId client, uint32_t subscription) {
  auto it = subscriptions_.find(client);
  if (it == subscriptions_.end() || !it->second.count(subscription))
    return "unsubscribe: unknown subscription id " + std::to_string(subscription);
  Channel* c = get(it->second[subscription]);
  std::erase_if(c->subscribers, [&](const Subscriber& s) {
    return s.client == client && s.subscription == subscription;
  });
  it->second.erase(subscription);
  return "";
}

void ChannelTable::remove_client(ClientId client) {
  auto it = subscriptions_.find(client);
  if (it == subscriptions_.end()) return;
  for (const auto& [sub, channel] : it->second)
    std::erase_if(get(channel)->subscribers,
                  [&](const Subscriber& s) { return s.client == client; });
  subscriptions_.erase(it);
}

bool ChannelTable::has_subscribers(uint32_t channel) const {
  const Channel* c = get(channel);
  return c && !c->subscribers.empty();
}

const std::vector<Subscriber>& ChannelTable::subscribers(uint32_t channel) const {
  static const std::vector<Subscriber> kNone;
  const Channel* c = get(channel);
  return c ? c->subscribers : kNone;
}

size_t ChannelTable::subscription_count(ClientId client) const {
  auto it = subscriptions_.find(client);
  return it == subscriptions_.end() ? 0 : it->second.size();
}

void ChannelTable::latch(uint32_t channel, uint64_t time_ns,
                         std::shared_ptr<const std::string> payload) {
  Channel* c = get(channel);
  if (!c || c->latch == 0) return;
  c->kept.push_back({time_ns, std::move(payload)});
  while (c->kept.size() > c->latch) c->kept.pop_front();
}

const std::deque<Latched>& ChannelTable::latched(uint32_t channel) const {
  static const std::deque<Latched> kNone;
  const Channel* c = get(channel);
  return c ? c->kept : kNone;
}

}  // namespace convoy::live
