// Radars and wheel odometers in the world (systems/radar_sensors.h, systems/wheel_odometry.h):
// a radar sees a box ahead at its range, azimuth and range rate, not one behind a barrier;
// the same seed gives the same scans; a rate above the step rate and a config entry with an
// unknown link or joint name the model, link and sensor; odometry follows a driving robot.
#include "systems/radar_sensors.h"

#include "convoy/datapacks.pb.h"
#include "convoy/radar.pb.h"
#include "sensor_config.h"
#include "systems/joint_controllers.h"
#include "systems/wheel_odometry.h"
#include "test_world.h"
#include "world_cache.h"

namespace convoy::world {
namespace {

using namespace testing;

// The ego (static, a 1 m box) carries the radar on its front face; a 2 m box 20 m ahead; a
// barrier 10 m out on the left hides a third box behind it.
const char* kWorld = R"(<?xml version="1.0"?>
<sdf version="1.7"><world name="w">
  <physics type="ode"><max_step_size>0.01</max_step_size></physics>
  <model name="ego"><static>%STATIC%</static>
    <link name="base"><gravity>false</gravity>
      <visual name="v"><geometry><box><size>1 1 1</size></box></geometry></visual>
      <sensor name="radar" type="custom"><pose>0.5 0 0 0 0 0</pose><update_rate>%RATE%</update_rate>
        <plugin filename="convoy_radar" name="front_radar">%PARAMS%</plugin></sensor>
      <sensor name="odom" type="custom"><plugin filename="convoy_wheel_odometry" name="o">
        <left_joint>jl</left_joint><right_joint>jr</right_joint><track>1.4</track></plugin></sensor>
    </link>
  </model>
  <model name="target"><pose>20 0 0 0 0 0</pose>
    <plugin name="convoy_class" filename="convoy_class"><class>car</class></plugin>
    <link name="body"><gravity>false</gravity><inertial><mass>1000</mass></inertial>
      <collision name="c"><geometry><box><size>2 2 2</size></box></geometry></collision>
      <visual name="v"><geometry><box><size>2 2 2</size></box></geometry></visual></link>
  </model>
  <model name="barrier_1"><static>true</static><pose>10 5 0 0 0 0</pose>
    <link name="l"><visual name="v"><geometry><box><size>1 3 3</size></box></geometry></visual></link>
  </model>
  <model name="hidden"><static>true</static><pose>20 10 0 0 0 0</pose>
    <plugin name="convoy_class" filename="convoy_class"><class>car</class></plugin>
    <link name="l"><visual name="v"><geometry><box><size>2 2 2</size></box></geometry></visual></link>
  </model>
</world></sdf>)";

const char* kQuiet =
    "<range_stddev>0</range_stddev><azimuth_stddev>0</azimuth_stddev>"
    "<elevation_stddev>0</elevation_stddev><range_rate_stddev>0</range_rate_stddev>"
    "<rcs_stddev>0</rcs_stddev><clutter>0</clutter>";

std::unique_ptr<WorldSystems> radar_world(const std::string& params, const std::string& rate,
                                          uint64_t seed, std::vector<ProvidedDataPack>* provided,
                                          bool ego_static = true) {
  std::string sdf = kWorld;
  sdf.replace(sdf.find("%STATIC%"), 8, ego_static ? "true" : "false");
  sdf.replace(sdf.find("%RATE%"), 6, rate);
  sdf.replace(sdf.find("%PARAMS%"), 8, params);
  auto world = make_world(write_world(sdf));
  world->add<RadarSensors>();
  *provided = world->configure({{"EngineTimestep", 0.01}, {"GazeboRNGSeed", seed}});
  world->physics().set_model_velocity("target", {-5, 0, 0});
  return world;
}

const data::RadarDetection* of(const data::Radar& r, const std::string& model) {
  for (const auto& d : r.detections())
    if (d.model() == model) return &d;
  return nullptr;
}

TEST(WorldRadar, SeesTheBoxAheadWithRangeAzimuthAndRangeRate) {
  std::vector<ProvidedDataPack> provided;
  auto world = radar_world(kQuiet, "20", 1, &provided);
  EXPECT_EQ(names(provided), (std::vector<std::string>{"ego::base::radar", "front_radar::radar"}));
  EXPECT_EQ(provided[0].type, "convoy.data.Radar");
  Got(*world, "ego::base::radar");  // asked for: scans from now on
  for (int i = 0; i < 50; ++i) world->step(10 * kMs);
  const auto r = Got(*world, "front_radar::radar").proto<data::Radar>();
  EXPECT_EQ(r.time_ns(), 500 * kMs);
  EXPECT_EQ(r.frame(), "ego::base::radar");
  const data::RadarDetection* car = of(r, "target");
  ASSERT_NE(car, nullptr);
  // the box has come 2.5 m closer: its near face at 16.5 m, the radar at 0.5 m
  EXPECT_NEAR(car->range(), 16.0, 1e-3);
  EXPECT_NEAR(car->azimuth(), 0.0, 1e-6);
  EXPECT_NEAR(car->elevation(), 0.0, 1e-6);
  EXPECT_NEAR(car->range_rate(), -5.0, 1e-3);
  EXPECT_EQ(car->class_name(), "car");
  EXPECT_NEAR(car->rcs(), radar::rcs_dbsm("car", 2, 2, 2), 1e-6);
  EXPECT_FALSE(car->clutter());
  EXPECT_NE(of(r, "barrier_1"), nullptr);
  EXPECT_EQ(of(r, "hidden"), nullptr);  // behind the barrier
  EXPECT_EQ(of(r, "ego"), nullptr);     // its own model
  EXPECT_TRUE(world->unchanged("front_radar::radar"));
  world->step(10 * kMs);
  EXPECT_TRUE(world->unchanged("front_radar::radar"));  // 20 Hz: next at 0.55 s
  for (int i = 0; i < 4; ++i) world->step(10 * kMs);
  EXPECT_FALSE(world->unchanged("front_radar::radar"));
  world->reset();  // the box back at 20 m, at rest
  const auto again = Got(*world, "ego::base::radar").proto<data::Radar>();
  EXPECT_EQ(again.time_ns(), 0);
  ASSERT_NE(of(again, "target"), nullptr);
  EXPECT_NEAR(of(again, "target")->range(), 18.5, 1e-3);
  EXPECT_NEAR(of(again, "target")->range_rate(), 0.0, 1e-9);
}

TEST(WorldRadar, TheRadarsOwnMotionAddsToTheRangeRate) {
  std::vector<ProvidedDataPack> provided;
  auto world = radar_world(kQuiet, "0", 1, &provided, /*ego_static=*/false);
  world->physics().set_model_velocity("ego", {3, 0, 0});
  Got(*world, "ego::base::radar");
  for (int i = 0; i < 20; ++i) world->step(10 * kMs);
  const auto r = Got(*world, "ego::base::radar").proto<data::Radar>();
  const data::RadarDetection* car = of(r, "target");
  const data::RadarDetection* barrier = of(r, "barrier_1");
  ASSERT_NE(car, nullptr);
  ASSERT_NE(barrier, nullptr);
  EXPECT_NEAR(car->range_rate(), -8.0, 1e-3);  // closing at 5 + 3 m/s
  EXPECT_NEAR(car->range(), 20 - 1 - 0.5 - 8 * 0.2, 1e-3);
  EXPECT_NEAR(barrier->range_rate(), -3.0 * std::cos(barrier->azimuth()), 0.02);
}

TEST(WorldRadar, SameSeedSameScansAndClutterIsLabelled) {
  const std::string noisy = "<clutter>4</clutter>";
  std::vector<ProvidedDataPack> provided;
  auto a = radar_world(noisy, "0", 7, &provided);
  auto b = radar_world(noisy, "0", 7, &provided);
  auto c = radar_world(noisy, "0", 8, &provided);
  std::string sa, sb, sc;
  int clutter = 0;
  for (auto* w : {a.get(), b.get(), c.get()}) Got(*w, "ego::base::radar");
  for (int i = 0; i < 10; ++i) {
    for (auto* w : {a.get(), b.get(), c.get()}) w->step(10 * kMs);
    const auto ra = Got(*a, "ego::base::radar").proto<data::Radar>();
    sa += ra.SerializeAsString();
    sb += Got(*b, "ego::base::radar").proto<data::Radar>().SerializeAsString();
    sc += Got(*c, "ego::base::radar").proto<data::Radar>().SerializeAsString();
    for (const auto& d : ra.detections())
      if (d.clutter()) {
        ++clutter;
        EXPECT_EQ(d.instance(), 0u);
        EXPECT_EQ(d.model(), "");
      }
  }
  EXPECT_EQ(sa, sb);
  EXPECT_NE(sa, sc);
  EXPECT_GT(clutter, 10);  // 4 a scan on average
}

TEST(WorldRadar, BadInputNamesModelLinkAndSensor) {
  std::vector<ProvidedDataPack> provided;
  EXPECT_NE(error_of([&] {
              radar_world(kQuiet, "200", 1, &provided);
            }).find("model 'ego' link 'base' sensor 'radar': <update_rate>: 200 Hz is above"),
            std::string::npos);
  std::string sdf = kWorld;
  sdf.replace(sdf.find("%STATIC%"), 8, "true");
  sdf.replace(sdf.find("%RATE%"), 6, "10");
  sdf.replace(sdf.find("%PARAMS%"), 8, "<max_range>-3</max_range>");
  const std::string e = error_of([&] { load_world(write_world(sdf)); });
  EXPECT_NE(e.find("model 'ego' link 'base' sensor 'radar': <max_range>: must be above"),
            std::string::npos)
      << e;
  WorldDesc d = load_world(data_file("wheel_robot.sdf"));
  const std::string link = error_of([&] {
    mount_config_sensors(
        {{"Sensors", {{{"Type", "radar"}, {"Name", "r"}, {"Model", "robot"}, {"Link", "roof"}}}}},
        0.01, &d);
  });
  EXPECT_EQ(link.rfind("Sensors/0: model 'robot' link 'roof' sensor 'r': model 'robot' has no "
                       "link 'roof'",
                       0),
            0u)
      << link;
  const std::string fov = error_of([&] {
    mount_config_sensors({{"Sensors",
                           {{{"Type", "radar"},
                             {"Name", "r"},
                             {"Model", "robot"},
                             {"Link", "chassis"},
                             {"HorizontalFov", 0}}}}},
                         0.01, &d);
  });
  EXPECT_EQ(fov,
            "Sensors/0/HorizontalFov: model 'robot' link 'chassis' sensor 'r': must be > 0 "
            "rad, got 0");
  const std::string joint = error_of([&] {
    mount_config_sensors({{"Sensors",
                           {{{"Type", "wheel_odometry"},
                             {"Name", "odo"},
                             {"Model", "robot"},
                             {"Link", "chassis"},
                             {"LeftJoint", "j_rl"},
                             {"RightJoint", "rear_right"}}}}},
                         0.01, &d);
  });
  EXPECT_NE(joint.find("model 'robot' link 'chassis' sensor 'odo': RightJoint: model 'robot' has "
                       "no joint 'rear_right'"),
            std::string::npos)
      << joint;
}

TEST(WorldRadar, RadarsAndOdometersGoThroughTheWorldCache) {
  std::string sdf = kWorld;
  sdf.replace(sdf.find("%STATIC%"), 8, "true");
  sdf.replace(sdf.find("%RATE%"), 6, "15");
  sdf.replace(sdf.find("%PARAMS%"), 8, "<max_range>77</max_range><clutter>0.5</clutter>");
  const WorldDesc parsed = load_world(write_world(sdf));
  const WorldDesc back = deserialize_world(serialize_world(parsed));
  const LinkDesc& l = back.models.at(0).links.at(0);
  ASSERT_EQ(l.radars.size(), 1u);
  EXPECT_EQ(l.radars[0].scoped_name, "ego::base::radar");
  EXPECT_EQ(l.radars[0].plugin_name, "front_radar");
  EXPECT_DOUBLE_EQ(l.radars[0].radar.max_range, 77);
  EXPECT_DOUBLE_EQ(l.radars[0].radar.clutter, 0.5);
  EXPECT_DOUBLE_EQ(l.radars[0].radar.update_rate, 15);
  EXPECT_NEAR(l.radars[0].pose.translation().x(), 0.5, 1e-12);
  ASSERT_EQ(l.odometers.size(), 1u);
  EXPECT_EQ(l.odometers[0].left_joint, "jl");
  EXPECT_EQ(l.odometers[0].right_joint, "jr");
  EXPECT_DOUBLE_EQ(l.odometers[0].odometry.track, 1.4);
  EXPECT_DOUBLE_EQ(l.odometers[0].odometry.wheel_radius, 0.3);
  EXPECT_EQ(serialize_world(back), serialize_world(parsed));
}

TEST(WorldWheelOdometry, ConfigMountedOdometerFollowsTheRobot) {
  WorldDesc d = load_world(data_file("wheel_robot.sdf"));
  mount_config_sensors({{"Sensors",
                         {{{"Type", "wheel_odometry"},
                           {"Name", "odo"},
                           {"Model", "robot"},
                           {"Link", "chassis"},
                           {"LeftJoint", "j_rl"},
                           {"RightJoint", "j_rr"},
                           {"WheelRadius", 0.1},
                           {"Track", 0.4},
                           {"UpdateRate", 10}}}}},
                       0.01, &d);
  WorldSystems world(std::move(d), 0, "test");
  world.add<JointControllers>();
  auto& odo = world.add<WheelOdometry>();
  const auto provided = world.configure({{"EngineTimestep", 0.01}});
  EXPECT_EQ(provided.back().name, "robot::chassis::odo");
  EXPECT_EQ(provided.back().type, "convoy.data.Odometry");
  ASSERT_EQ(odo.count(), 1u);
  const int chassis = world.physics().link_index("robot::chassis");
  const Eigen::Vector3d start = world.physics().link_pose(chassis).translation();
  for (const char* j : {"robot::j_fl", "robot::j_fr", "robot::j_rl", "robot::j_rr"}) {
    data::Joint target;
    target.set_velocity(4);
    send_proto(world, j, target);
  }
  for (int i = 0; i < 200; ++i) world.step(10 * kMs);
  const auto m = Got(world, "robot::chassis::odo").proto<data::Odometry>();
  EXPECT_EQ(m.time_ns(), 2000 * kMs);
  const double travelled = (world.physics().link_pose(chassis).translation() - start).norm();
  EXPECT_GT(travelled, 0.3);
  EXPECT_NEAR(m.x(), travelled, 0.05 * travelled);
  EXPECT_NEAR(m.y(), 0, 0.02);
  EXPECT_NEAR(m.speed(), 0.4, 0.05);  // 4 rad/s x 0.1 m
  world.reset();
  EXPECT_EQ(Got(world, "robot::chassis::odo").proto<data::Odometry>().x(), 0);
}

}  // namespace
}  // namespace convoy::world
