// Link states (systems/link_states.h): every link of a link plugin's model under the plugin's
// and the scoped name, its pose and velocities in the world frame.
#include "systems/link_states.h"

#include <cmath>

#include "convoy/datapacks.pb.h"
#include "test_world.h"

namespace convoy::world {
namespace {

using namespace testing;

TEST(WorldLinkStates, EveryLinkOfThePluginsModelUnderBothNames) {
  auto world = make_world(data_file("wheel_robot.sdf"));
  world->add<LinkStates>();
  const auto provided = world->configure(nlohmann::json::object());
  EXPECT_EQ(names(provided),
            (std::vector<std::string>{"robot_link_plugin::chassis", "robot::chassis",
                                      "robot_link_plugin::wheel_fl", "robot::wheel_fl",
                                      "robot_link_plugin::wheel_fr", "robot::wheel_fr",
                                      "robot_link_plugin::wheel_rl", "robot::wheel_rl",
                                      "robot_link_plugin::wheel_rr", "robot::wheel_rr"}));
  EXPECT_EQ(provided[0].type, "convoy.data.Link");
  EXPECT_EQ(provided[0].model, 1);
  const auto chassis = Got(*world, "robot::chassis").proto<data::Link>();
  ASSERT_EQ(chassis.position_size(), 3);
  EXPECT_FLOAT_EQ(chassis.position(2), 0.1f);  // as loaded
  const auto wheel = Got(*world, "robot_link_plugin::wheel_fl").proto<data::Link>();
  EXPECT_FLOAT_EQ(wheel.position(0), 0.15f);
  EXPECT_FLOAT_EQ(wheel.position(1), 0.2f);
  ASSERT_EQ(wheel.rotation_size(), 4);  // x y z w: -90 degrees about x
  EXPECT_NEAR(wheel.rotation(0), -std::sqrt(0.5), 1e-4);
  EXPECT_NEAR(wheel.rotation(3), std::sqrt(0.5), 1e-4);
  world->step(200 * kMs);  // it falls onto its wheels
  const auto fallen = Got(*world, "robot::chassis").proto<data::Link>();
  EXPECT_EQ(fallen.linear_velocity_size(), 3);
  EXPECT_EQ(fallen.angular_velocity_size(), 3);
  EXPECT_TRUE(Got(*world, "robot::nothing").empty());
}

}  // namespace
}  // namespace convoy::world
