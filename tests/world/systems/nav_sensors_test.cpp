// IMU and GNSS (systems/nav_sensors.h): the datapacks under the scoped and the plugin's names,
// readings of a body at rest and falling, update rates, reset, and a rate above the step
// rate refused with the model, link and sensor named.
#include "systems/nav_sensors.h"

#include "convoy/nav_sensors.pb.h"
#include "test_world.h"

namespace convoy::world {
namespace {

using namespace testing;

const char* kWorld = R"(<?xml version="1.0"?>
<sdf version="1.7"><world name="w">
  <physics type="ode"><max_step_size>0.001</max_step_size></physics>
  <model name="ball"><pose>1 2 10 0 0 0</pose>
    <link name="body"><inertial><mass>1</mass></inertial>
      <collision name="c"><geometry><sphere><radius>0.2</radius></sphere></geometry></collision>
      <sensor name="imu" type="imu"><update_rate>%RATE%</update_rate>
        <plugin name="imu_plugin" filename="libgazebo_ros_imu_sensor.so"/></sensor>
      <sensor name="gnss" type="navsat"><update_rate>10</update_rate></sensor>
    </link>
  </model>
</world></sdf>)";

std::unique_ptr<WorldSystems> nav_world(const std::string& rate = "100") {
  std::string sdf = kWorld;
  sdf.replace(sdf.find("%RATE%"), 6, rate);
  auto world = make_world(write_world(sdf));
  world->add<NavSensors>();
  return world;
}

TEST(WorldNavSensors, DatapacksUnderBothNames) {
  auto world = nav_world();
  const auto provided = world->configure({{"EngineTimestep", 0.01}});
  EXPECT_EQ(names(provided),
            (std::vector<std::string>{"ball::body::imu", "imu_plugin::imu", "ball::body::gnss"}));
  EXPECT_EQ(provided[0].type, "convoy.data.Imu");
  EXPECT_EQ(provided[2].type, "convoy.data.NavSat");
}

TEST(WorldNavSensors, FallingReadsWeightlessAndGnssFollows) {
  auto world = nav_world();
  world->configure({{"EngineTimestep", 0.01}});
  const auto still = Got(*world, "ball::body::imu").proto<data::Imu>();  // before a step
  ASSERT_EQ(still.linear_acceleration_size(), 3);
  EXPECT_NEAR(still.linear_acceleration(2), 9.8, 1e-9);  // no difference yet: at rest
  for (int i = 0; i < 30; ++i) world->step(10 * kMs);
  const auto imu = Got(*world, "imu_plugin::imu").proto<data::Imu>();
  EXPECT_EQ(imu.time_ns(), 300 * kMs);
  EXPECT_NEAR(imu.linear_acceleration(2), 0.0, 1e-6);  // free fall
  EXPECT_EQ(imu.orientation_size(), 4);
  const auto gnss = Got(*world, "ball::body::gnss").proto<data::NavSat>();
  EXPECT_EQ(gnss.time_ns(), 300 * kMs);  // 10 Hz: due at 0.3 s
  EXPECT_NEAR(gnss.velocity_up(), -9.8 * 0.3, 0.02);
  EXPECT_NEAR(gnss.latitude_deg(), 2 / 111134.0, 1e-7);  // no <spherical_coordinates>: 0, 0
  EXPECT_TRUE(world->unchanged("ball::body::gnss"));
  world->step(10 * kMs);
  EXPECT_TRUE(world->unchanged("ball::body::gnss"));  // next at 0.4 s
  EXPECT_FALSE(world->unchanged("ball::body::imu"));
  world->reset();
  const auto again = Got(*world, "ball::body::imu").proto<data::Imu>();
  EXPECT_EQ(again.time_ns(), 0);
  EXPECT_NEAR(again.linear_acceleration(2), 9.8, 1e-9);
}

TEST(WorldNavSensors, RateAboveTheStepRateNamesTheSensor) {
  auto world = nav_world("200");
  try {
    world->configure({{"EngineTimestep", 0.01}});
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("model 'ball' link 'body' sensor 'imu': <update_rate>"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace convoy::world
