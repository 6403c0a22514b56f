// The ego's state (systems/ego_state.h): the wheeled robot as a road user, its box from its
// collision shapes, speed and acceleration as it drives; EgoModels.
#include "systems/ego_state.h"

#include "convoy/datapacks.pb.h"
#include "systems/joint_controllers.h"
#include "test_world.h"

namespace convoy::world {
namespace {

using namespace testing;

std::unique_ptr<WorldSystems> robot_world(const nlohmann::json& config,
                                          std::vector<ProvidedDataPack>* provided) {
  auto world = make_world(data_file("wheel_robot.sdf"));
  world->add<JointControllers>();
  world->add<EgoState>();
  *provided = world->configure(config);
  return world;
}

TEST(WorldEgoState, TheRobotIsARoadUserWithItsBoxSpeedAndAcceleration) {
  std::vector<ProvidedDataPack> provided;
  auto world =
      robot_world(nlohmann::json::object(), &provided);  // the model with a joint controller plugin
  EXPECT_EQ(provided.back().name, "robot::road_user");
  EXPECT_EQ(provided.back().type, "convoy.data.RoadUser");
  EXPECT_EQ(provided.back().model, -1);
  world->step(100 * kMs);
  auto u = Got(*world, "robot::road_user").proto<data::RoadUser>();
  EXPECT_EQ(u.id(), "robot");
  EXPECT_EQ(u.model(), "robot");
  EXPECT_EQ(u.category(), class_of(world->context().desc->models[1]));
  EXPECT_NEAR(u.length(), 0.5, 1e-9);  // wheel to wheel
  EXPECT_NEAR(u.width(), 0.44, 1e-5);  // (the wheels turned by -1.5708)
  EXPECT_NEAR(u.length_offset(), 0.0, 1e-9);
  EXPECT_EQ(u.time_ns(), 100 * kMs);
  EXPECT_NEAR(u.speed(), 0.0, 1e-3);
  for (const char* j : {"robot::j_fl", "robot::j_fr", "robot::j_rl", "robot::j_rr"}) {
    data::Joint target;
    target.set_velocity(4);
    send_proto(*world, j, target);
  }
  world->step(500 * kMs);
  const auto before = Got(*world, "robot::road_user").proto<data::RoadUser>();
  world->step(100 * kMs);
  u = Got(*world, "robot::road_user").proto<data::RoadUser>();
  EXPECT_GT(u.speed(), 0.2);
  EXPECT_NEAR(u.vx(), u.speed(), 1e-3);
  EXPECT_NEAR(u.acceleration(), (u.speed() - before.speed()) / 0.1, 1e-6);
  EXPECT_GT(u.x(), before.x());
  EXPECT_NEAR(u.yaw(), 0.0, 0.05);
}

TEST(WorldEgoState, EgoModelsNamesThemAndAnUnknownOneIsAnError) {
  std::vector<ProvidedDataPack> provided;
  auto world = robot_world({{"EgoModels", nlohmann::json::array()}}, &provided);
  EXPECT_EQ(provided.size(), 8u);  // the joints only
  EXPECT_EQ(error_of([&] {
              robot_world({{"EgoModels", {"nope"}}}, &provided);
            }),
            "EgoModels: no model 'nope' with a link in the world");
  world = robot_world({{"EgoModels", {"robot"}}}, &provided);
  EXPECT_EQ(provided.back().name, "robot::road_user");
}

}  // namespace
}  // namespace convoy::world
