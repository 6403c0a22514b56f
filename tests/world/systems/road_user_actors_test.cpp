// Road users as actors (systems/road_user_actors.h): an actor appears with its first state,
// leaves when absent or after ActorTimeout and comes back; the camera's ground truth shows
// it; bad road users are errors naming engine, datapack and road user.
#include "systems/road_user_actors.h"

#include <algorithm>

#include "systems/camera_datapacks.h"
#include "systems/contacts.h"
#include "test_world.h"

namespace convoy::world {
namespace {

using namespace testing;

class WorldActors : public ::testing::Test {
 protected:
  void start(const nlohmann::json& config = nlohmann::json::object()) {
    world_ = make_world(data_file("actor_world.sdf"));  // camera at (-5, 0, 2) along +x
    actors_ = &world_->add<RoadUserActors>();
    world_->add<CameraDatapacks>();
    world_->add<Contacts>();
    world_->configure(config);
  }
  bool present(const std::string& id) {
    const auto* a = actors_->actor(id);
    return a && a->present;
  }
  std::vector<std::string> boxes() {
    std::vector<std::string> out;
    const nlohmann::json got = Got(*world_, "rig_camera::cam::boxes").json();
    for (const auto& b : got["boxes"]) out.push_back(b["model"]);
    return out;
  }
  std::unique_ptr<WorldSystems> world_;
  RoadUserActors* actors_ = nullptr;
};

TEST_F(WorldActors, AnActorAppearsLeavesWhenAbsentAndComesBack) {
  start();
  const nlohmann::json car = {{"id", "car1"}, {"category", "car"}, {"x", 10.0}, {"y", 0.0}};
  send_json(*world_, "traffic", {{"users", {car}}});
  EXPECT_EQ(actors_->actor("car1"), nullptr);  // posed at the next step
  world_->step(20 * kMs);
  ASSERT_TRUE(present("car1"));
  EXPECT_EQ(actors_->actor("car1")->cls, "car");
  EXPECT_EQ(boxes(), std::vector<std::string>{"car1"});
  nlohmann::json gone = car;
  gone["absent"] = true;
  send_json(*world_, "traffic", gone);
  world_->step(20 * kMs);
  EXPECT_FALSE(present("car1"));
  world_->step(40 * kMs);  // the camera's next frame
  EXPECT_TRUE(boxes().empty());
  send_json(*world_, "traffic", car);
  world_->step(20 * kMs);
  EXPECT_TRUE(present("car1"));
}

TEST_F(WorldActors, ANewRoadUserTakesOverARemovedActorOfItsShape) {
  start();
  const nlohmann::json car = {{"id", "car1"}, {"category", "car"}, {"x", 10.0}, {"y", 0.0}};
  send_json(*world_, "traffic", car);
  world_->step(20 * kMs);
  nlohmann::json gone = car;
  gone["absent"] = true;
  send_json(*world_, "traffic", gone);
  world_->step(20 * kMs);
  // A bus (another shape) cannot take it; car2 (the same model and size) does.
  send_json(*world_, "traffic",
            {{"users",
              {{{"id", "bus1"}, {"category", "bus"}, {"x", 30.0}, {"y", 6.0}},
               {{"id", "car2"}, {"category", "car"}, {"x", 12.0}, {"y", 0.0}}}}});
  world_->step(20 * kMs);
  EXPECT_EQ(actors_->actor_count(), 2u);
  EXPECT_EQ(actors_->actor("car1"), nullptr);
  ASSERT_TRUE(present("car2"));
  EXPECT_TRUE(present("bus1"));
  world_->step(40 * kMs);  // the camera's next frame names the new road user
  auto seen = boxes();
  std::sort(seen.begin(), seen.end());
  EXPECT_EQ(seen, (std::vector<std::string>{"bus1", "car2"}));
  // car1 comes back: every actor of its shape is taken, so it gets a new one.
  send_json(*world_, "traffic", car);
  world_->step(20 * kMs);
  EXPECT_EQ(actors_->actor_count(), 3u);
  EXPECT_TRUE(present("car1"));
  EXPECT_TRUE(present("car2"));
  // A car of another size is another shape.
  send_json(*world_, "traffic", gone);
  world_->step(20 * kMs);
  send_json(*world_, "traffic",
            {{"id", "long"}, {"category", "car"}, {"length", 7.5}, {"x", -20.0}, {"y", 8.0}});
  world_->step(20 * kMs);
  EXPECT_EQ(actors_->actor_count(), 4u);
}

TEST_F(WorldActors, AnActorBackBeforeItIsTakenOverKeepsIt) {
  start({{"ActorTimeout", 0.3}});
  send_json(*world_, "traffic", {{"id", "bike"}, {"category", "cyclist"}, {"x", 12.0}});
  world_->step(20 * kMs);
  world_->step(400 * kMs);
  EXPECT_FALSE(present("bike"));
  send_json(*world_, "traffic", {{"id", "bike"}, {"category", "cyclist"}, {"x", 13.0}});
  world_->step(20 * kMs);
  EXPECT_TRUE(present("bike"));
  // Its actor is no longer free: another cyclist gets a new one.
  send_json(*world_, "traffic", {{"id", "bike2"}, {"category", "cyclist"}, {"x", 30.0}});
  world_->step(20 * kMs);
  EXPECT_TRUE(present("bike"));
  EXPECT_TRUE(present("bike2"));
  EXPECT_EQ(actors_->actor_count(), 2u);
}

TEST_F(WorldActors, AnActorNotHeardOfForActorTimeoutLeaves) {
  start({{"ActorTimeout", 0.3}});
  send_json(*world_, "traffic", {{"id", "bike"}, {"category", "cyclist"}, {"x", 12.0}});
  world_->step(20 * kMs);
  world_->step(280 * kMs);  // 0.28 s since last seen
  EXPECT_TRUE(present("bike"));
  world_->step(40 * kMs);
  EXPECT_FALSE(present("bike"));
}

TEST_F(WorldActors, WithActorTimeoutZeroAnActorStays) {
  start({{"ActorTimeout", 0}});
  send_json(*world_, "traffic", {{"id", "bus"}, {"category", "bus"}, {"x", 30.0}});
  world_->step(5000 * kMs);
  EXPECT_TRUE(present("bus"));
}

TEST_F(WorldActors, ProtobufRoadUsersUnderAnyName) {
  start();
  data::RoadUsers users;
  auto* a = users.add_users();
  a->set_id("p1");
  a->set_category("pedestrian");
  a->set_x(8);
  auto* b = users.add_users();
  b->set_id("p2");
  b->set_category("pedestrian");
  b->set_x(8);
  b->set_y(3);
  send_proto(*world_, "crowd", users);
  world_->step(20 * kMs);
  EXPECT_TRUE(present("p1"));
  EXPECT_TRUE(present("p2"));
}

TEST_F(WorldActors, BadRoadUsersAreErrorsNamingEngineDatapackAndId) {
  // (A failed step ends the run: a fresh world for each.)
  start();
  send_json(*world_, "traffic", {{"id", "x"}, {"category", "plane"}});
  EXPECT_EQ(error_of([&] { world_->step(20 * kMs); }),
            "engine 'test': datapack 'traffic': road user 'x': category 'plane' is not one of "
            "car, truck, bus, pedestrian, cyclist");
  start();
  send_json(*world_, "traffic", {{"id", "c"}, {"category", "car"}, {"x", 10.0}});
  world_->step(20 * kMs);
  send_json(*world_, "traffic", {{"id", "c"}, {"category", "bus"}, {"x", 10.0}});
  EXPECT_EQ(error_of([&] { world_->step(20 * kMs); }),
            "engine 'test': datapack 'traffic': road user 'c': was 'car', now 'bus': an id cannot "
            "change its category");
  start();
  const std::string bad_key = error_of([&] {
    send_json(*world_, "traffic", {{"id", "c"}, {"colour", "red"}});
  });
  EXPECT_EQ(bad_key.rfind("engine 'test': datapack 'traffic': ", 0), 0u) << bad_key;
  EXPECT_NE(bad_key.find("colour"), std::string::npos) << bad_key;
}

TEST_F(WorldActors, TwoRoadUsersAppearingOnTheSameSpotIsAnError) {
  start();
  send_json(*world_, "traffic",
            {{"users",
              {{{"id", "a"}, {"category", "car"}, {"x", 20.0}, {"y", 5.0}},
               {{"id", "b"}, {"category", "car"}, {"x", 20.5}, {"y", 5.0}}}}});
  const std::string e = error_of([&] { world_->step(20 * kMs); });
  EXPECT_EQ(e.rfind("engine 'test': road users 'a' and 'b' are placed on the same spot", 0), 0u)
      << e;
}

TEST_F(WorldActors, ResetRemovesTheActors) {
  start();
  send_json(*world_, "traffic", {{"id", "car1"}, {"category", "car"}, {"x", 10.0}});
  world_->step(20 * kMs);
  world_->reset();
  EXPECT_EQ(actors_->actor("car1"), nullptr);
  world_->step(20 * kMs);
  EXPECT_TRUE(boxes().empty());
}

}  // namespace
}  // namespace convoy::world
