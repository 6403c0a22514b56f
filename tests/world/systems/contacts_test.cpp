// Contacts (systems/contacts.h): a pair is recorded when it starts touching, once, and again
// only after half a second apart; world models from the physics, actors from their boxes.
#include "systems/contacts.h"

#include <cmath>

#include "systems/road_user_actors.h"
#include "test_world.h"

namespace convoy::world {
namespace {

using namespace testing;

class WorldContacts : public ::testing::Test {
 protected:
  void start(const std::filesystem::path& file) {
    world_ = make_world(file);
    world_->add<RoadUserActors>();
    contacts_ = &world_->add<Contacts>();
    provided_ = world_->configure(nlohmann::json::object());
  }
  // A car standing at (20, 30) and a bus at x (facing -x, 5 m/s as its message says).
  void place_bus(double x) {
    send_json(*world_, "traffic",
              {{"users",
                {{{"id", "traffic/a"}, {"category", "car"}, {"x", 20.0}, {"y", 30.0}},
                 {{"id", "traffic/b"},
                  {"category", "bus"},
                  {"x", x},
                  {"y", 31.0},
                  {"yaw", 3.14159},
                  {"speed", 5.0}}}}});
    world_->step(20 * kMs);
  }
  std::unique_ptr<WorldSystems> world_;
  Contacts* contacts_ = nullptr;
  std::vector<ProvidedDataPack> provided_;
};

TEST_F(WorldContacts, ActorsOverlappingAreRecordedOnceThenAgainAfterHalfASecondApart) {
  start(data_file("actor_world.sdf"));
  EXPECT_EQ(names(provided_), std::vector<std::string>{"collisions"});
  place_bus(60);  // apart
  place_bus(22);  // into the car
  ASSERT_EQ(contacts_->records().size(), 1u);
  const auto& r = contacts_->records()[0];
  EXPECT_EQ(r["a"], "traffic/a");  // names in sorted order
  EXPECT_EQ(r["b"], "traffic/b");
  EXPECT_EQ(r["class_a"], "car");
  EXPECT_EQ(r["class_b"], "bus");
  EXPECT_DOUBLE_EQ(r["t"].get<double>(), 0.04);
  EXPECT_NEAR(r["relative_speed_mps"].get<double>(), 5.0, 1e-4);
  for (int i = 0; i < 10; ++i) place_bus(22);  // still touching: no new record
  for (int i = 0; i < 15; ++i) place_bus(60);  // 0.3 s apart
  place_bus(22);
  EXPECT_EQ(contacts_->records().size(), 1u);
  for (int i = 0; i < 30; ++i) place_bus(60);  // 0.6 s apart
  place_bus(22);
  EXPECT_EQ(contacts_->records().size(), 2u);
  EXPECT_EQ(Got(*world_, "collisions").json(), contacts_->records());
}

TEST_F(WorldContacts, AModelFallingOntoAnotherIsRecordedOnceNotTheGround) {
  start(write_world(
      "<?xml version='1.0'?><sdf version='1.7'><world name='w'>"
      "<model name='ground'><static>true</static><link name='link'><collision name='c'>"
      "<geometry><plane><normal>0 0 1</normal><size>50 50</size></plane></geometry>"
      "</collision></link></model>"
      "<model name='table'><static>true</static><pose>0 0 0.5 0 0 0</pose><link name='link'>"
      "<collision name='c'><geometry><box><size>2 2 1</size></box></geometry></collision>"
      "<visual name='v'><geometry><box><size>2 2 1</size></box></geometry></visual></link><plugin "
      "name='convoy_class' filename='convoy_class'><class>other</class></plugin>"
      "</model>"
      "<model name='crate'><pose>0 0 1.7 0 0 0</pose><link name='link'><inertial><mass>5</mass>"
      "</inertial><collision name='c'><geometry><box><size>0.4 0.4 0.4</size></box></geometry>"
      "</collision><visual name='v'><geometry><box><size>0.4 0.4 0.4</size></box></geometry>"
      "</visual></link><plugin name='convoy_class' filename='convoy_class'><class>barrier"
      "</class></plugin></model></world></sdf>"));
  world_->step(2000 * kMs);  // falls 0.5 m (0.32 s), then rests on the table
  ASSERT_EQ(contacts_->records().size(), 1u) << contacts_->records().dump();
  const auto& r = contacts_->records()[0];
  EXPECT_EQ(r["a"], "crate");
  EXPECT_EQ(r["b"], "table");
  EXPECT_EQ(r["class_a"], "barrier");
  EXPECT_NEAR(r["t"].get<double>(), 2.0, 1e-12);  // the engine's time of the step
  // Read after the physics step that made the contact: the solver has stopped the crate
  // already (an actor's speed, from its messages, is the speed it came with).
  EXPECT_GE(r["relative_speed_mps"].get<double>(), 0.0);
  EXPECT_LT(r["relative_speed_mps"].get<double>(), std::sqrt(2 * 9.8 * 0.5));
  world_->reset();
  EXPECT_TRUE(contacts_->records().empty());
}

}  // namespace
}  // namespace convoy::world
