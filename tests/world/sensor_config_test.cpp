// The world engine's config-mounted sensors (engines/gazebo_grpc/sensor_config.h): each entry
// becomes the description an SDF <sensor> of its link would give.
#include "sensor_config.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

namespace convoy::world {
namespace {

using nlohmann::json;

WorldDesc world() {
  // One file per test and process: ctest runs this binary's tests side by side.
  const auto* test = ::testing::UnitTest::GetInstance()->current_test_info();
  const auto file = std::filesystem::temp_directory_path() /
                    ("convoy_sensor_config_" + std::string(test->name()) + "_" +
                     std::to_string(::getpid()) + ".sdf");
  std::ofstream(file) << R"(<?xml version="1.0"?><sdf version="1.7"><world name="w">
    <model name="car"><pose>1 2 0 0 0 0</pose><link name="body"><inertial><mass>1</mass>
    </inertial></link></model></world></sdf>)";
  WorldDesc d = load_world(file);
  std::filesystem::remove(file);
  return d;
}

json sensors(json list) { return {{"Sensors", list}}; }

TEST(SensorConfig, MountsALidarAndNavSensorsOnTheLink) {
  WorldDesc d = world();
  mount_config_sensors(
      sensors({{{"Type", "gpu_lidar"},
                {"Name", "lidar"},
                {"Model", "car"},
                {"Link", "body"},
                {"Pose", {0.5, 0, 1.9, 0, 0, 0}},
                {"Preset", "hdl32"},
                {"RangeMax", 60},
                {"NoiseStddev", 0.02}},
               {{"Type", "imu"},
                {"Name", "imu"},
                {"Model", "car"},
                {"Link", "body"},
                {"UpdateRate", 50},
                {"SDF",
                 "<imu><linear_acceleration><x><noise type='gaussian'><stddev>0.1"
                 "</stddev></noise></x></linear_acceleration></imu>"}},
               {{"Type", "navsat"}, {"Name", "gnss"}, {"Model", "car"}, {"Link", "body"}}}),
      0.02, &d);
  const LinkDesc& body = d.models.at(0).links.at(0);
  ASSERT_EQ(body.lidars.size(), 1u);
  const LidarDesc& l = body.lidars[0];
  EXPECT_EQ(l.scoped_name, "car::body::lidar");
  EXPECT_EQ((std::pair{l.model, l.link}), (std::pair<std::string, std::string>{"car", "body"}));
  EXPECT_EQ(l.lidar.vertical.samples, 32);
  EXPECT_EQ(l.lidar.horizontal.samples, 1024);
  EXPECT_NEAR(l.lidar.vertical.min_angle, -30.67 * M_PI / 180, 1e-9);
  EXPECT_EQ(l.lidar.range_max, 60);
  EXPECT_EQ(l.lidar.noise_stddev, 0.02);
  EXPECT_EQ(l.lidar.update_rate, 10);
  EXPECT_NEAR(l.pose.translation().z(), 1.9, 1e-12);
  ASSERT_EQ(body.nav_sensors.size(), 2u);
  EXPECT_EQ(body.nav_sensors[0].kind, NavSensorDesc::kImu);
  EXPECT_EQ(body.nav_sensors[0].imu.linear_acceleration[0].stddev, 0.1);
  EXPECT_EQ(body.nav_sensors[1].kind, NavSensorDesc::kNavSat);
  EXPECT_EQ(body.nav_sensors[1].scoped_name, "car::body::gnss");
}

std::string error_of(json entry, double step_s = 0.02) {
  WorldDesc d = world();
  try {
    mount_config_sensors(sensors({entry}), step_s, &d);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "no error";
}

TEST(SensorConfig, BadInputNamesModelLinkAndSensor) {
  json e = {{"Type", "lidar"}, {"Name", "s"}, {"Model", "car"}, {"Link", "body"}};
  EXPECT_EQ(error_of(e), "no error");
  json roof = e;
  roof["Link"] = "roof";
  EXPECT_EQ(error_of(roof),
            "Sensors/0: model 'car' link 'roof' sensor 's': model 'car' has no link 'roof' "
            "(links: body)");
  json truck = e;
  truck["Model"] = "truck";
  EXPECT_EQ(error_of(truck),
            "Sensors/0: model 'truck' link 'body' sensor 's': no model 'truck' in the world");
  json zero = e;
  zero["VerticalSamples"] = 0;
  EXPECT_EQ(error_of(zero),
            "Sensors/0/VerticalSamples: model 'car' link 'body' sensor 's': must "
            "be a whole number of samples >= 1, got 0");
  json fast = e;
  fast["UpdateRate"] = 200;
  EXPECT_NE(error_of(fast).find("200 Hz is above the engine's step rate"), std::string::npos);
  json bad_sdf = e;
  bad_sdf["Type"] = "imu";
  bad_sdf["SDF"] = "<imu><angular_velocity>";
  EXPECT_NE(error_of(bad_sdf).find("Sensors/0: model 'car' link 'body' sensor 's': its SDF is "
                                   "refused"),
            std::string::npos);
}

}  // namespace
}  // namespace convoy::world
