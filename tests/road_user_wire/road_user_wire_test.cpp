// The in-place reader against protobuf's own parser: the same fields from random messages
// with every other field set too, the same verdict on every truncation, and bad bytes refused.
#include "road_user_wire/road_user_wire.h"

#include <gtest/gtest.h>

#include <random>
#include <string>
#include <vector>

#include "convoy/road_users.pb.h"

namespace convoy::road_user_wire {
namespace {

data::RoadUsers random_users(uint64_t seed, int n) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> v(-500, 500);
  data::RoadUsers users;
  for (int i = 0; i < n; ++i) {
    data::RoadUser* u = users.add_users();
    u->set_id("car_" + std::to_string(i));
    u->set_category(i % 3 ? "car" : "pedestrian");
    u->set_model("sedan");
    u->set_absent(i % 7 == 3);
    u->set_x(v(rng));
    u->set_y(v(rng));
    u->set_z(v(rng));
    u->set_yaw(v(rng));
    if (i % 4) u->set_speed(v(rng));  // some left at 0: not on the wire
    u->set_acceleration(v(rng));
    u->set_length(v(rng));
    u->set_width(v(rng));
    u->set_length_offset(v(rng));
    u->set_lights(static_cast<uint32_t>(i));
    u->set_road("r" + std::to_string(i));
    u->set_lane(-i);
    u->set_time_ns(1000 * i);
  }
  users.set_time_ns(123456789);
  return users;
}

void expect_same(const data::RoadUser& want, const UserFields& got) {
  EXPECT_EQ(got.id, want.id());
  EXPECT_EQ(got.category, want.category());
  EXPECT_EQ(got.absent, want.absent());
  EXPECT_EQ(got.x, want.x());
  EXPECT_EQ(got.y, want.y());
  EXPECT_EQ(got.yaw, want.yaw());
  EXPECT_EQ(got.speed, want.speed());
  EXPECT_EQ(got.length, want.length());
  EXPECT_EQ(got.width, want.width());
  EXPECT_EQ(got.length_offset, want.length_offset());
}

TEST(RoadUserWire, TheFieldsProtobufReads) {
  for (uint64_t seed = 1; seed <= 5; ++seed) {
    const data::RoadUsers users = random_users(seed, 40);
    const std::string bytes = users.SerializeAsString();
    std::vector<UserFields> got;
    ASSERT_TRUE(for_each_user(bytes, [&](const UserFields& u) { got.push_back(u); }));
    ASSERT_EQ(got.size(), static_cast<size_t>(users.users_size()));
    for (int i = 0; i < users.users_size(); ++i) expect_same(users.users(i), got[i]);
    UserFields one;
    ASSERT_TRUE(read_user(users.users(5).SerializeAsString(), &one));
    EXPECT_EQ(one.x, users.users(5).x());
  }
}

TEST(RoadUserWire, ALaterValueWinsAsInProtobuf) {
  data::RoadUser a, b;
  a.set_id("first");
  a.set_x(1);
  b.set_x(2);
  b.set_absent(true);
  const std::string bytes = a.SerializeAsString() + b.SerializeAsString();  // merged: x = 2
  data::RoadUser merged;
  ASSERT_TRUE(merged.ParseFromString(bytes));
  UserFields got;
  ASSERT_TRUE(read_user(bytes, &got));
  expect_same(merged, got);
}

TEST(RoadUserWire, TruncatedBytesFailWhereProtobufFails) {
  const std::string bytes = random_users(9, 6).SerializeAsString();
  for (size_t n = 0; n < bytes.size(); ++n) {
    const std::string cut = bytes.substr(0, n);
    data::RoadUsers parsed;
    const bool want = parsed.ParseFromString(cut);
    int seen = 0;
    const bool ok = for_each_user(cut, [&](const UserFields&) { ++seen; });
    ASSERT_EQ(ok, want) << "cut at " << n;
    if (ok) EXPECT_EQ(seen, parsed.users_size());
  }
}

TEST(RoadUserWire, BadBytes) {
  UserFields u;
  EXPECT_FALSE(read_user(std::string("\x00\x01", 2), &u));  // field number 0
  EXPECT_FALSE(read_user("\x0b", &u));                      // a group (wire type 3)
  EXPECT_FALSE(read_user("\x0a\x05ab", &u));                // a string longer than the rest
  EXPECT_FALSE(read_user("\x29\x00\x00", &u));              // x cut short
  EXPECT_FALSE(for_each_user("\x0a\x02\x29\x00", [](const UserFields&) {}));
}

}  // namespace
}  // namespace convoy::road_user_wire
