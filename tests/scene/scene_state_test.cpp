// scene::SceneState and ScenePacer: what the scene keeps from the datapacks.
#include "scene/scene_state.h"

#include <gtest/gtest.h>

#include "scene_test_util.h"

namespace convoy::scene {
namespace {

using nlohmann::json;
using testing::json_datapack;
using testing::proto_datapack;
using testing::user;

const datapack::BlobReader& blobs() { return datapack::inline_blob_reader(); }

bool ingest(SceneState& s, const std::string& engine, const engine::DataPack& dp, int64_t t = 0) {
  return s.ingest(engine, datapack::View(dp, blobs()), t);
}

TEST(SceneState, TakesInAProtobufRoadUser) {
  SceneState s;
  auto u = user("car_0", "car", 10, 20, 0.5);
  u.set_speed(7.5);
  EXPECT_TRUE(ingest(s, "car_0", proto_datapack("state", u)));
  ASSERT_EQ(s.users().count("car_0"), 1u);
  const SceneUser& su = s.users().at("car_0");
  EXPECT_EQ(su.state.x(), 10);
  EXPECT_EQ(su.state.speed(), 7.5);
  EXPECT_FALSE(su.ego);
  EXPECT_EQ(su.source, "car_0/state");
  EXPECT_EQ(s.ego(), nullptr);
}

TEST(SceneState, TakesInJsonRoadUsersWithDefaultsAndIgnoresOtherJson) {
  SceneState s;
  EXPECT_TRUE(ingest(
      s, "ped",
      json_datapack(
          "state",
          {{"id", "ped_0"}, {"category", "pedestrian"}, {"x", 1}, {"y", 2.5}, {"extra", "x"}})));
  ASSERT_EQ(s.users().count("ped_0"), 1u);
  EXPECT_EQ(s.users().at("ped_0").state.y(), 2.5);
  EXPECT_EQ(s.users().at("ped_0").state.length(), 0);
  // A list and {"users": [...]} hold several.
  EXPECT_TRUE(ingest(s, "crowd",
                     json_datapack("all", json::array({{{"id", "a"}, {"x", 0}, {"y", 0}},
                                                       {{"id", "b"}, {"x", 1}, {"y", 0}}}))));
  EXPECT_TRUE(
      ingest(s, "more", json_datapack("all", {{"users", {{{"id", "c"}, {"x", 2}, {"y", 0}}}}})));
  EXPECT_EQ(s.users().size(), 4u);
  // No id, or a position that is no number: not a road user.
  EXPECT_FALSE(ingest(s, "eng", json_datapack("target", {{"speed", 3}, {"x", 1}})));
  EXPECT_FALSE(ingest(s, "eng", json_datapack("odd", {{"id", "q"}, {"x", "1"}, {"y", 0}})));
  EXPECT_EQ(s.users().size(), 4u);
}

TEST(SceneState, AnAbsentRoadUserIsDeleted) {
  SceneState s;
  ingest(s, "car_0", proto_datapack("state", user("car_0", "car", 0, 0)));
  auto gone = user("car_0", "car", 0, 0);
  gone.set_absent(true);
  ingest(s, "car_0", proto_datapack("state", gone));
  EXPECT_TRUE(s.users().empty());
  EXPECT_EQ(s.deleted(), std::set<std::string>{"car_0"});
  s.clear_deleted();
  EXPECT_TRUE(s.deleted().empty());
  // Back again: no longer among the deleted.
  ingest(s, "car_0", proto_datapack("state", gone));
  ingest(s, "car_0", proto_datapack("state", user("car_0", "car", 1, 0)));
  EXPECT_TRUE(s.deleted().empty());
  EXPECT_EQ(s.users().size(), 1u);
}

TEST(SceneState, ARoadUserSetDropsWhomItNoLongerLists) {
  SceneState s;
  data::RoadUsers set;
  *set.add_users() = user("sumo/v1", "car", 0, 0);
  *set.add_users() = user("sumo/v2", "truck", 5, 0);
  ingest(s, "sumo", proto_datapack("road_users", set));
  ingest(s, "car_0", proto_datapack("state", user("car_0", "car", 9, 9)));
  EXPECT_EQ(s.users().size(), 3u);
  set.mutable_users()->RemoveLast();
  ingest(s, "sumo", proto_datapack("road_users", set));
  EXPECT_EQ(s.users().size(), 2u);
  EXPECT_EQ(s.deleted(), std::set<std::string>{"sumo/v2"});
  EXPECT_EQ(s.users().count("car_0"), 1u);  // another source's: kept
}

TEST(SceneState, TheWorldEnginesRoadUserIsTheEgoWithATrail) {
  SceneOptions o;
  o.world_engines = {"gazebo"};
  SceneState s(o);
  // 0.125 m per 20 ms for 1.6 s: 10 m, a trail point every 0.5 m.
  for (int i = 0; i <= 80; ++i)
    ingest(s, "gazebo",
           proto_datapack("smart_car::road_user", user("smart_car", "car", 0.125 * i, 0)),
           i * 20000000LL);
  ASSERT_NE(s.ego(), nullptr);
  EXPECT_EQ(s.ego()->state.id(), "smart_car");
  EXPECT_EQ(s.trail().size(), 21u);
  EXPECT_NEAR(s.trail().back().p.x, 10.0, 1e-9);
  // Older than 60 s: dropped.
  ingest(s, "gazebo", proto_datapack("smart_car::road_user", user("smart_car", "car", 50, 0)),
         62000000000LL);
  EXPECT_EQ(s.trail().size(), 1u);
  // A `*::road_user` datapack is an ego from any engine; another name from another engine is not.
  SceneState t;
  ingest(t, "world", proto_datapack("bot::road_user", user("bot", "car", 0, 0)));
  ingest(t, "car_0", proto_datapack("state", user("car_0", "car", 0, 0)));
  EXPECT_TRUE(t.users().at("bot").ego);
  EXPECT_FALSE(t.users().at("car_0").ego);
}

TEST(SceneState, SignalsAndRoute) {
  SceneOptions o;
  o.route = {{0, 0, 0}, {10, 0, 0}};
  SceneState s(o);
  EXPECT_EQ(s.route().size(), 2u);
  EXPECT_TRUE(ingest(s, "lights",
                     json_datapack("traffic_lights", {{"time_ns", 0},
                                                      {"signals", {{"s1", "red"}, {"s2", "green"}}},
                                                      {"junctions", json::object()}})));
  EXPECT_EQ(s.signals().at("s1"), "red");
  ingest(s, "lights", json_datapack("traffic_lights", {{"signals", {{"s1", "yellow"}}}}));
  EXPECT_EQ(s.signals().at("s1"), "yellow");
  EXPECT_EQ(s.signals().at("s2"), "green");
  ingest(s, "planner", json_datapack("plan", {{"route", {{1, 2}, {3, 4}, {5, 6}}}}));
  EXPECT_EQ(s.route().size(), 3u);
  EXPECT_EQ(s.route()[1].y, 4);
}

TEST(ScenePacer, OneUpdatePerPeriodForCompleteCycles) {
  ScenePacer p(10);
  std::vector<int64_t> sent;
  for (int cycle = 0; cycle <= 25; ++cycle) {
    const int64_t t = cycle * 20000000LL;
    for (int dp = 0; dp < 3; ++dp)  // several datapacks per cycle: one decision
      if (auto due = p.due(t, true)) sent.push_back(*due);
  }
  EXPECT_EQ(sent, (std::vector<int64_t>{0, 100000000, 200000000, 300000000, 400000000}));
  ScenePacer off(0);
  EXPECT_FALSE(off.due(0, true));
  EXPECT_FALSE(off.due(1000000000, true));
  ScenePacer empty(10);
  EXPECT_FALSE(empty.due(0, false));
  EXPECT_FALSE(empty.due(1000000000, false));
}

}  // namespace
}  // namespace convoy::scene
