#include "live/send_queue.h"

#include <gtest/gtest.h>

namespace convoy::live {
namespace {

OutMessage data(const std::string& s) { return {true, "", std::make_shared<const std::string>(s)}; }

TEST(SendQueue, KeepsOrderAndSendsControlFirst) {
  SendQueue q;
  q.push_data(data("a"));
  q.push_data(data("b"));
  q.push_control({false, "", std::make_shared<const std::string>("advertise")});
  EXPECT_EQ(*q.pop()->body, "advertise");
  EXPECT_EQ(*q.pop()->body, "a");
  EXPECT_EQ(*q.pop()->body, "b");
  EXPECT_FALSE(q.pop());
  EXPECT_TRUE(q.empty());
  EXPECT_EQ(q.dropped(), 0u);
  EXPECT_EQ(q.pushed(), 2u);
}

TEST(SendQueue, DropsTheOldestDataWhenFullAndCountsThem) {
  SendQueue q({/*max_messages=*/3, /*max_bytes=*/1 << 20});
  for (int i = 0; i < 10; ++i) q.push_data(data(std::to_string(i)));
  for (int i = 0; i < 5; ++i) q.push_control({false, "", std::make_shared<const std::string>("c")});
  EXPECT_EQ(q.dropped(), 7u);
  for (int i = 0; i < 5; ++i) EXPECT_EQ(*q.pop()->body, "c");  // control: never dropped
  EXPECT_EQ(*q.pop()->body, "7");
  EXPECT_EQ(*q.pop()->body, "8");
  EXPECT_EQ(*q.pop()->body, "9");
  EXPECT_FALSE(q.pop());
}

TEST(SendQueue, BoundsTheBytesToo) {
  SendQueue q({/*max_messages=*/100, /*max_bytes=*/250});
  for (int i = 0; i < 5; ++i) q.push_data(data(std::string(100, char('a' + i))));
  EXPECT_EQ(q.dropped(), 3u);
  EXPECT_EQ(q.bytes(), 200u);
  EXPECT_EQ(q.pop()->body->front(), 'd');
  // A message larger than the bound alone still goes.
  q.push_data(data(std::string(1000, 'x')));
  EXPECT_EQ(q.dropped(), 4u);
  EXPECT_EQ(q.pop()->body->size(), 1000u);
  EXPECT_EQ(q.bytes(), 0u);
}

TEST(SendQueue, CountsTheHeadInTheSize) {
  OutMessage m{true, std::string(13, '\0'), std::make_shared<const std::string>("xyz")};
  EXPECT_EQ(m.size(), 16u);
}

}  // namespace
}  // namespace convoy::live
