// The world engine's "Sensors" key as the coordinator checks it (src/config/sensor_keys.h).
#include "config/sensor_keys.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

namespace convoy::config {
namespace {

using nlohmann::json;

json lidar_engine(json overrides = json::object()) {
  json s = {{"Type", "gpu_lidar"}, {"Name", "lidar"}, {"Model", "car"}, {"Link", "body"}};
  s.update(overrides);
  return {{"Sensors", json::array({s})}};
}

std::string only_problem(const json& engine, double step_s = 0.02) {
  Problems problems;
  read_sensor_entries(engine, step_s, "/EngineConfigs/0", &problems);
  if (problems.size() != 1) return "problems: " + std::to_string(problems.size());
  return problems[0].first + " | " + problems[0].second;
}

TEST(SensorKeys, PresetAndOverrides) {
  Problems problems;
  auto entries = read_sensor_entries(
      lidar_engine({{"Preset", "hdl64"}, {"HorizontalSamples", 512}, {"Pose", {1, 2, 3}}}), 0.02,
      "", &problems);
  ASSERT_TRUE(problems.empty());
  ASSERT_EQ(entries.size(), 1u);
  const SensorEntry& e = entries[0];
  EXPECT_TRUE(e.is_lidar());
  EXPECT_EQ(e.v_samples, 64);
  EXPECT_EQ(e.h_samples, 512);
  EXPECT_NEAR(e.v_min, -24.9 * M_PI / 180, 1e-12);
  EXPECT_EQ(e.range_max, 120);
  EXPECT_EQ(e.update_rate, 10);
  EXPECT_EQ(e.pose[2], 3);
  // the default preset is a VLP-16
  entries = read_sensor_entries(lidar_engine(), 0.02, "", &problems);
  EXPECT_EQ(entries.at(0).v_samples, 16);
  EXPECT_EQ(entries.at(0).h_samples, 1800);
}

TEST(SensorKeys, BadValuesNameTheFieldAndTheSensor) {
  const std::string who = "model 'car' link 'body' sensor 'lidar': ";
  EXPECT_EQ(only_problem(lidar_engine({{"VerticalSamples", 0}})),
            "/EngineConfigs/0/Sensors/0/VerticalSamples | " + who +
                "must be a whole number of samples >= 1, got 0");
  EXPECT_EQ(only_problem(lidar_engine({{"RangeMin", -1}})),
            "/EngineConfigs/0/Sensors/0/RangeMin | " + who + "must be >= 0 m, got -1");
  EXPECT_EQ(
      only_problem(lidar_engine({{"RangeMax", 0.5}})),
      "/EngineConfigs/0/Sensors/0/RangeMax | " + who + "must be above RangeMin (0.9 m), got 0.5");
  EXPECT_EQ(only_problem(lidar_engine({{"UpdateRate", 100}})),
            "/EngineConfigs/0/Sensors/0/UpdateRate | " + who +
                "100 Hz is above the engine's step rate (1 / EngineTimestep = 50 Hz)");
  EXPECT_EQ(only_problem(lidar_engine({{"Type", "sonar"}})),
            "/EngineConfigs/0/Sensors/0/Type | " + who +
                "unknown type 'sonar' (lidar, gpu_lidar, ray, gpu_ray, imu, navsat, radar, "
                "wheel_odometry)");
  EXPECT_EQ(only_problem(lidar_engine({{"Preset", "vlp99"}})),
            "/EngineConfigs/0/Sensors/0/Preset | " + who +
                "unknown preset 'vlp99' (vlp16, hdl32, hdl64)");
  EXPECT_EQ(only_problem(lidar_engine({{"Pose", {1, 2}}})),
            "/EngineConfigs/0/Sensors/0/Pose | " + who +
                "must be [x, y, z] or [x, y, z, roll, pitch, yaw], got [1,2]");
  json two = lidar_engine();
  two["Sensors"].push_back(two["Sensors"][0]);
  EXPECT_EQ(only_problem(two), "/EngineConfigs/0/Sensors/1/Name | " + who +
                                   "a second sensor of that name on that link");
}

TEST(SensorKeys, ModelsAndLinksLookedUpInTheSdf) {
  const auto dir = std::filesystem::temp_directory_path() / "convoy_sensor_keys_test";
  std::filesystem::create_directories(dir / "models" / "car");
  std::ofstream(dir / "world.sdf") << "<sdf version='1.7'><world name='w'>"
                                      "<model name='box'><model name=\"inner\"><link "
                                      "name='in'/></model><link name='body'/></model>"
                                      "<include><uri>model://car</uri></include>"
                                      "<include><uri>model://elsewhere</uri><name>far</name>"
                                      "</include></world></sdf>";
  std::ofstream(dir / "models" / "car" / "model.sdf")
      << "<sdf version='1.7'><model name='car'><link name='chassis'/>"
         "<!-- <link name='commented'/> --></model></sdf>";
  auto check = [&](const std::string& model, const std::string& link) {
    json engine = lidar_engine({{"Model", model}, {"Link", link}});
    engine["GazeboWorldFile"] = (dir / "world.sdf").string();
    Problems problems;
    read_sensor_keys(engine, 0.02, "/E", &problems);
    return problems.empty() ? std::string("ok") : problems[0].first + " | " + problems[0].second;
  };
  EXPECT_EQ(check("box", "body"), "ok");
  EXPECT_EQ(check("car", "chassis"), "ok");
  EXPECT_EQ(check("far", "anything"), "ok");  // its file is not found: left to the engine
  EXPECT_EQ(check("car", "commented"),
            "/E/Sensors/0/Link | model 'car' link 'commented' sensor 'lidar': model 'car' has no "
            "link 'commented' (links: chassis)");
  EXPECT_EQ(check("box", "wheel"),
            "/E/Sensors/0/Link | model 'box' link 'wheel' sensor 'lidar': model 'box' has no link "
            "'wheel' (links: body)");
  EXPECT_NE(check("box", "in"), "ok");         // a nested model's link is not its parent's
  EXPECT_EQ(check("box::inner", "in"), "ok");  // nested models are left to the engine
  EXPECT_EQ(check("truck", "body"),
            "/E/Sensors/0/Model | model 'truck' link 'body' sensor 'lidar': no model 'truck' in "
            "the world file or GazeboSDFModels (models: box, car, far)");
  // a large generated world (no regex recursion): 50,000 links in one model
  std::ofstream big(dir / "world.sdf");
  big << "<sdf version='1.7'><world name='w'><model name='city'>";
  for (int i = 0; i < 50000; ++i) big << "<link name='l" << i << "'><visual name='v'/></link>\n";
  big << "</model></world></sdf>";
  big.close();
  EXPECT_EQ(check("city", "l49999"), "ok");
  EXPECT_NE(check("city", "l50000"), "ok");
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace convoy::config
