// Initial speeds (systems/initial_speeds.h, model_inserts.h): the report's smart car inserted
// with an InitSpeed rolls on at that speed with no command, its wheels found by the rule and
// spinning at speed / radius; a reset starts it again; a bad InitSpeed is an error naming the
// entry and the key.
#include "systems/initial_speeds.h"

#include <cmath>
#include <cstdlib>

#include "convoy/road_users.pb.h"
#include "model_inserts.h"
#include "physics_world.h"
#include "systems/ego_state.h"
#include "systems/joint_controllers.h"
#include "test_world.h"

namespace convoy::world {
namespace {

using namespace testing;

const std::string kModels = CONVOY_SMART_CAR_MODELS;  // the folder holding smart_car/
const std::string kCar = kModels + "/smart_car/model.sdf";

constexpr const char* kFlatWorld = R"(<?xml version="1.0"?>
<sdf version="1.7">
  <world name="flat">
    <physics type="ode"><max_step_size>0.001</max_step_size></physics>
    <model name="ground">
      <static>true</static>
      <link name="link">
        <collision name="c"><geometry><plane><normal>0 0 1</normal><size>500 500</size></plane></geometry></collision>
      </link>
    </model>
  </world>
</sdf>)";

nlohmann::json car_config(const nlohmann::json& speed, const std::string& name = "smart_car") {
  nlohmann::json car = {{"File", kCar}, {"InitPose", {0, 0, 0, 0, 0, 0.5}}, {"InitSpeed", speed}};
  if (!name.empty()) car["Name"] = name;
  return {{"GazeboSDFModels", {car}}};
}

// The flat world with the smart car of `config`, its joint controllers, initial speed and
// ego state.
std::unique_ptr<WorldSystems> car_world(const nlohmann::json& config) {
  ::setenv("CONVOY_MODEL_PATH", kModels.c_str(), 1);  // the car's meshes: model://smart_car/...
  auto world = std::make_unique<WorldSystems>(
      load_world(write_world(kFlatWorld), read_model_inserts(config)), /*seed=*/0, "test");
  world->add<JointControllers>();
  world->add<InitialSpeeds>();
  world->add<EgoState>();
  world->configure(config);
  return world;
}

data::RoadUser car(WorldSystems& world) {
  return Got(world, "smart_car::road_user").proto<data::RoadUser>();
}

TEST(WorldInitialSpeeds, TheSmartCarsWheelsAreItsFourTyres) {
  ::setenv("CONVOY_MODEL_PATH", kModels.c_str(), 1);
  const auto models = load_model(kCar, "car", Eigen::Isometry3d::Identity());
  const auto wheels = find_wheels(models.at(0));
  ASSERT_EQ(wheels.size(), 4u);  // not the steering links (no collision) nor the camera
  const char* names[] = {"car::front_left_wheel_joint", "car::front_right_wheel_joint",
                         "car::rear_left_wheel_joint", "car::rear_right_wheel_joint"};
  for (size_t i = 0; i < wheels.size(); ++i) {
    EXPECT_EQ(wheels[i].joint, names[i]);
    EXPECT_DOUBLE_EQ(wheels[i].radius, 0.3);
    EXPECT_NEAR(std::abs(wheels[i].axis.y()), 1.0, 1e-6);
  }
}

TEST(WorldInitialSpeeds, TheCarRollsOnAtItsInitSpeedWithNoCommand) {
  auto world = car_world(car_config(10));
  const int rear = world->physics().joint_index("smart_car::rear_left_wheel_joint");
  EXPECT_NEAR(world->physics().joint_state(rear).velocity, 10 / 0.3, 1e-9);
  auto start = car(*world);
  EXPECT_NEAR(start.speed(), 10.0, 1e-6);
  world->step(500 * kMs);
  auto u = car(*world);
  EXPECT_NEAR(u.speed(), 10.0, 0.2);
  // about 5 m along the heading (yaw 0.5), none across it
  const double dx = u.x() - start.x(), dy = u.y() - start.y();
  EXPECT_NEAR(dx * std::cos(0.5) + dy * std::sin(0.5), 5.0, 0.15);
  EXPECT_NEAR(-dx * std::sin(0.5) + dy * std::cos(0.5), 0.0, 0.05);
  EXPECT_NEAR(u.yaw(), 0.5, 0.01);
  world->step(1500 * kMs);
  EXPECT_NEAR(car(*world).speed(), 10.0, 0.3);
  std::printf("smart car, InitSpeed 10, no command: %.3f m/s after 0.5 s, %.3f m/s after 2 s\n",
              u.speed(), car(*world).speed());
}

TEST(WorldInitialSpeeds, AResetStartsItRollingAgainAndNoInitSpeedLeavesItAtRest) {
  auto world = car_world(car_config(10, /*name=*/""));  // its own name: smart_car
  world->step(300 * kMs);
  world->reset();
  EXPECT_NEAR(car(*world).speed(), 10.0, 1e-6);
  world->step(300 * kMs);
  EXPECT_NEAR(car(*world).speed(), 10.0, 0.2);
  auto still = car_world(car_config(0));
  still->step(300 * kMs);
  EXPECT_NEAR(car(*still).speed(), 0.0, 0.05);
}

TEST(WorldInitialSpeeds, ANegativeOrNonNumericInitSpeedIsAnError) {
  EXPECT_EQ(error_of([] { read_model_inserts(car_config(-1)); }),
            "GazeboSDFModels/0/InitSpeed: must be a number >= 0 (m/s), got -1");
  EXPECT_EQ(error_of([] { read_model_inserts(car_config("fast")); }),
            "GazeboSDFModels/0/InitSpeed: must be a number >= 0 (m/s), got \"fast\"");
  EXPECT_EQ(error_of([] {
              read_model_inserts({{"GazeboSDFModels", {{{"File", kCar}, {"InitPose", {1, 2}}}}}});
            }),
            "GazeboSDFModels/0/InitPose: must be [x, y, z] or [x, y, z, roll, pitch, yaw], got "
            "[1,2]");
}

}  // namespace
}  // namespace convoy::world
