#include "live/channel_table.h"

#include <gtest/gtest.h>

namespace convoy::live {
namespace {

ChannelInfo info(const std::string& topic) { return {0, topic, "json", "X", "{}", "jsonschema"}; }

TEST(ChannelTable, GivesIdsFromOne) {
  ChannelTable t;
  EXPECT_EQ(t.add(info("a")), 1u);
  EXPECT_EQ(t.add(info("b")), 2u);
  EXPECT_EQ(t.find(2)->topic, "b");
  EXPECT_EQ(t.find(2)->id, 2u);
  EXPECT_EQ(t.find(0), nullptr);
  EXPECT_EQ(t.find(3), nullptr);
  EXPECT_EQ(t.all().size(), 2u);
}

TEST(ChannelTable, SubscribesAndUnsubscribes) {
  ChannelTable t;
  const uint32_t a = t.add(info("a")), b = t.add(info("b"));
  EXPECT_FALSE(t.has_subscribers(a));
  EXPECT_EQ(t.subscribe(1, {10, a}), "");
  EXPECT_EQ(t.subscribe(2, {10, a}), "");  // ids are per client
  EXPECT_EQ(t.subscribe(1, {11, b}), "");
  EXPECT_TRUE(t.has_subscribers(a));
  ASSERT_EQ(t.subscribers(a).size(), 2u);
  EXPECT_EQ(t.subscribers(a)[1].client, 2u);
  EXPECT_EQ(t.subscribers(a)[1].subscription, 10u);
  EXPECT_EQ(t.unsubscribe(1, 10), "");
  EXPECT_EQ(t.subscribers(a).size(), 1u);
  EXPECT_EQ(t.subscription_count(1), 1u);
  t.remove_client(2);
  EXPECT_FALSE(t.has_subscribers(a));
  EXPECT_TRUE(t.has_subscribers(b));
  t.remove_client(1);
  EXPECT_FALSE(t.has_subscribers(b));
  EXPECT_EQ(t.subscription_count(1), 0u);
}

TEST(ChannelTable, RefusesBadSubscriptionsAndChangesNothing) {
  ChannelTable t;
  const uint32_t a = t.add(info("a")), b = t.add(info("b"));
  EXPECT_NE(t.subscribe(1, {0, 99}).find("unknown channel id 99"), std::string::npos);
  EXPECT_EQ(t.subscribe(1, {0, a}), "");
  EXPECT_NE(t.subscribe(1, {0, b}).find("subscription id 0 is already in use"), std::string::npos);
  EXPECT_NE(t.subscribe(1, {1, a}).find("already subscribed to channel"), std::string::npos);
  EXPECT_NE(t.unsubscribe(1, 5).find("unknown subscription id 5"), std::string::npos);
  EXPECT_NE(t.unsubscribe(7, 0).find("unknown subscription id 0"), std::string::npos);
  EXPECT_EQ(t.subscribers(a).size(), 1u);
  EXPECT_FALSE(t.has_subscribers(b));
  EXPECT_TRUE(t.subscribers(99).empty());
}

TEST(ChannelTable, LatchedChannelsKeepTheirLastMessages) {
  ChannelTable t;
  const uint32_t log = t.add(info("log"), 2), plain = t.add(info("x"));
  for (int i = 0; i < 3; ++i) {
    t.latch(log, i, std::make_shared<const std::string>(std::to_string(i)));
    t.latch(plain, i, std::make_shared<const std::string>(std::to_string(i)));
  }
  ASSERT_EQ(t.latched(log).size(), 2u);
  EXPECT_EQ(*t.latched(log)[0].payload, "1");
  EXPECT_EQ(t.latched(log)[1].time_ns, 2u);
  EXPECT_TRUE(t.latched(plain).empty());
}

}  // namespace
}  // namespace convoy::live
