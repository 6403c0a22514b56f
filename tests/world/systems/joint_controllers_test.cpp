// Joint controllers and link states (systems/joint_controllers.h, systems/link_states.h) on
// the wheeled robot: a velocity target through either name turns the wheels, the datapacks
// read the joints and links, a reset brings back the SDF's targets.
#include "systems/joint_controllers.h"

#include <cmath>

#include "convoy/datapacks.pb.h"
#include "systems/link_states.h"
#include "test_world.h"

namespace convoy::world {
namespace {

using namespace testing;

class WorldJointControllers : public ::testing::Test {
 protected:
  void SetUp() override {
    world_ = make_world(data_file("wheel_robot.sdf"));
    joints_ = &world_->add<JointControllers>();
    world_->add<LinkStates>();
    provided_ = world_->configure(nlohmann::json::object());
  }
  void spin_wheels(const std::string& prefix, double omega) {
    for (const char* j : {"j_fl", "j_fr", "j_rl", "j_rr"}) {
      data::Joint target;
      target.set_velocity(static_cast<float>(omega));
      send_proto(*world_, prefix + j, target);
    }
  }
  std::unique_ptr<WorldSystems> world_;
  JointControllers* joints_ = nullptr;
  std::vector<ProvidedDataPack> provided_;
};

TEST_F(WorldJointControllers, EachJointAndLinkUnderThePluginsNameAndTheScopedName) {
  const auto n = names(provided_);
  ASSERT_EQ(n.size(), 4u * 2 + 5u * 2);  // 4 joints, 5 links
  EXPECT_EQ(n[0], "robot_joint_plugin::j_fl");
  EXPECT_EQ(n[1], "robot::j_fl");
  EXPECT_EQ(n[8], "robot_link_plugin::chassis");
  EXPECT_EQ(n[9], "robot::chassis");
  EXPECT_EQ(provided_[0].type, "convoy.data.Joint");
  EXPECT_EQ(provided_[8].type, "convoy.data.Link");
}

TEST_F(WorldJointControllers, AVelocityTargetTurnsTheWheelsAndMovesTheRobot) {
  spin_wheels("robot_joint_plugin::", 4.0);
  EXPECT_DOUBLE_EQ(joints_->target("robot::j_fl"), 4.0);  // the same controller
  world_->step(2000 * kMs);
  const auto j = Got(*world_, "robot::j_fl").proto<data::Joint>();
  EXPECT_NEAR(j.velocity(), 4.0, 0.2);
  const auto link = Got(*world_, "robot_link_plugin::chassis").proto<data::Link>();
  ASSERT_EQ(link.position_size(), 3);
  EXPECT_GT(link.position(0), 0.5);  // omega r = 0.4 m/s for about 2 s
  EXPECT_NEAR(link.linear_velocity(0), 0.4, 0.05);
  ASSERT_EQ(link.rotation_size(), 4);  // x y z w
  EXPECT_NEAR(link.rotation(3), 1.0, 1e-3);
}

TEST_F(WorldJointControllers, ResetBringsBackTheSdfTargetsAndTheRobotsStart) {
  spin_wheels("robot::", 4.0);
  world_->step(500 * kMs);
  world_->reset();
  EXPECT_DOUBLE_EQ(joints_->target("robot::j_fl"), 0.0);
  const auto link = Got(*world_, "robot::chassis").proto<data::Link>();
  EXPECT_NEAR(link.position(0), 0.0, 1e-9);
  world_->step(500 * kMs);
  EXPECT_NEAR(Got(*world_, "robot::j_fl").proto<data::Joint>().velocity(), 0.0, 0.05);
}

TEST_F(WorldJointControllers, AJointDatapackOfAnotherTypeOrAnUnknownNameIsAnError) {
  EXPECT_EQ(error_of([&] {
              send_json(*world_, "robot::j_fl", {{"velocity", 1}});
            }),
            "datapack 'robot::j_fl' must be a GazeboJointDataPack");
  data::Joint target;
  EXPECT_EQ(error_of([&] { send_proto(*world_, "robot::j_nope", target); }),
            "engine 'test' has no writable datapack 'robot::j_nope' (joint datapacks are "
            "<joint plugin>::<joint>)");
  EXPECT_TRUE(Got(*world_, "robot::j_nope").empty());
}

}  // namespace
}  // namespace convoy::world
