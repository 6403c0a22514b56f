// The parsed-world cache (world_cache.h): a hit gives the same description as parsing, a
// changed included file or a corrupt entry is rebuilt, and the format round-trips.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "world_cache.h"

namespace convoy::world {
namespace {

namespace fs = std::filesystem;

void write(const fs::path& p, const std::string& text) {
  fs::create_directories(p.parent_path());
  std::ofstream(p) << text;
}

std::string model_sdf(double size) {
  return "<?xml version='1.0'?><sdf version='1.7'><model name='crate'><static>true</static>"
         "<link name='link'><collision name='c'><geometry><box><size>" +
         std::to_string(size) +
         " 1 1</size></box></geometry></collision>"
         "<visual name='v'><geometry><box><size>1 1 1</size></box></geometry></visual></link>"
         "<plugin name='convoy_class' filename='convoy_class'><class>other</class></plugin>"
         "</model></sdf>";
}

class CacheTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ =
        fs::temp_directory_path() /
        ("convoy-cache-test-" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
         "-" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    setenv("CONVOY_CACHE_DIR", (dir_ / "cache").c_str(), 1);
    write(
        dir_ / "models" / "crate" / "model.config",
        "<?xml version='1.0'?><model><name>crate</name><sdf version='1.7'>model.sdf</sdf></model>");
    write(dir_ / "models" / "crate" / "model.sdf", model_sdf(2.0));
    world_ = dir_ / "world.sdf";
    write(
        world_,
        "<?xml version='1.0'?><sdf version='1.7'><world name='w'>"
        "<include><uri>model://crate</uri><name>crate_1</name><pose>1 2 0 0 0 0.5</pose></include>"
        "<model name='ball'><link name='link'><inertial><mass>2</mass></inertial>"
        "<collision name='c'><geometry><sphere><radius>0.5</radius></sphere></geometry></collision>"
        "</link></model></world></sdf>");
  }
  void TearDown() override {
    unsetenv("CONVOY_CACHE_DIR");
    fs::remove_all(dir_);
  }
  fs::path dir_, world_;
};

TEST_F(CacheTest, AHitGivesTheSameDescriptionAsParsing) {
  CacheResult r;
  WorldDesc first = load_world_cached(world_, {}, &r);
  EXPECT_EQ(r, CacheResult::kMiss);
  WorldDesc second = load_world_cached(world_, {}, &r);
  EXPECT_EQ(r, CacheResult::kHit);
  const std::string parsed = serialize_world(load_world(world_));
  EXPECT_EQ(serialize_world(first), parsed);
  EXPECT_EQ(serialize_world(second), parsed);
  ASSERT_EQ(second.models.size(), 2u);
  EXPECT_EQ(second.models[0].name, "crate_1");
  EXPECT_EQ(second.models[0].cls, "other");
  EXPECT_DOUBLE_EQ(second.models[0].links[0].collisions[0].shape.size.x(), 2.0);
  EXPECT_NEAR(second.models[0].links[0].pose.translation().y(), 2.0, 1e-12);
  EXPECT_DOUBLE_EQ(second.models[1].links[0].mass, 2.0);
  EXPECT_TRUE(second.shadows);  // no <scene><shadows>: SDF's default
}

TEST_F(CacheTest, TheScenesShadowsSettingIsKept) {
  write(world_,
        "<?xml version='1.0'?><sdf version='1.7'><world name='w'>"
        "<scene><shadows>false</shadows><background>0.1 0.2 0.3 1</background></scene>"
        "</world></sdf>");
  CacheResult r;
  EXPECT_FALSE(load_world_cached(world_, {}, &r).shadows);
  EXPECT_EQ(r, CacheResult::kMiss);
  WorldDesc hit = load_world_cached(world_, {}, &r);
  EXPECT_EQ(r, CacheResult::kHit);
  EXPECT_FALSE(hit.shadows);
  EXPECT_FLOAT_EQ(hit.background[2], 0.3f);
}

TEST_F(CacheTest, LidarsAreKept) {
  write(world_,
        "<?xml version='1.0'?><sdf version='1.7'><world name='w'>"
        "<model name='car'><link name='roof'><inertial><mass>1</mass></inertial>"
        "<sensor name='scanner' type='gpu_lidar'><pose>0.1 0 0.3 0 0 0</pose>"
        "<update_rate>10</update_rate><lidar><scan><horizontal><samples>64</samples>"
        "<min_angle>-1</min_angle><max_angle>1</max_angle></horizontal><vertical>"
        "<samples>4</samples><min_angle>-0.2</min_angle><max_angle>0.1</max_angle></vertical>"
        "</scan><range><min>0.5</min><max>60</max></range><noise><type>gaussian</type>"
        "<stddev>0.02</stddev></noise></lidar></sensor></link></model></world></sdf>");
  CacheResult r;
  const std::string parsed = serialize_world(load_world_cached(world_, {}, &r));
  EXPECT_EQ(r, CacheResult::kMiss);
  WorldDesc hit = load_world_cached(world_, {}, &r);
  EXPECT_EQ(r, CacheResult::kHit);
  EXPECT_EQ(serialize_world(hit), parsed);
  ASSERT_EQ(hit.models[0].links[0].lidars.size(), 1u);
  const LidarDesc& d = hit.models[0].links[0].lidars[0];
  EXPECT_EQ(d.scoped_name, "car::roof::scanner");
  EXPECT_EQ(d.model, "car");
  EXPECT_EQ(d.link, "roof");
  EXPECT_NEAR(d.pose.translation().z(), 0.3, 1e-12);
  EXPECT_EQ(d.lidar.horizontal.samples, 64);
  EXPECT_EQ(d.lidar.vertical.samples, 4);
  EXPECT_DOUBLE_EQ(d.lidar.vertical.min_angle, -0.2);
  EXPECT_DOUBLE_EQ(d.lidar.range_max, 60);
  EXPECT_DOUBLE_EQ(d.lidar.update_rate, 10);
  EXPECT_TRUE(d.lidar.gaussian_noise);
  EXPECT_DOUBLE_EQ(d.lidar.noise_stddev, 0.02);
}

TEST_F(CacheTest, ImusGnssAndTheEarthFrameAreKept) {
  write(world_,
        "<?xml version='1.0'?><sdf version='1.7'><world name='w'>"
        "<spherical_coordinates><surface_model>EARTH_WGS84</surface_model>"
        "<latitude_deg>48.2</latitude_deg><longitude_deg>16.37</longitude_deg>"
        "<elevation>171</elevation><heading_deg>10</heading_deg></spherical_coordinates>"
        "<model name='car'><link name='roof'><inertial><mass>1</mass></inertial>"
        "<sensor name='imu' type='imu'><pose>0 0.2 0 0 0 0</pose><update_rate>50</update_rate>"
        "<imu><angular_velocity><z><noise type='gaussian'><stddev>0.01</stddev>"
        "<dynamic_bias_stddev>0.002</dynamic_bias_stddev>"
        "<dynamic_bias_correlation_time>400</dynamic_bias_correlation_time></noise></z>"
        "</angular_velocity></imu></sensor>"
        "<sensor name='gnss' type='navsat'><navsat><position_sensing><horizontal>"
        "<noise type='gaussian'><stddev>1.5</stddev></noise></horizontal></position_sensing>"
        "</navsat></sensor></link></model></world></sdf>");
  CacheResult r;
  const std::string parsed = serialize_world(load_world_cached(world_, {}, &r));
  EXPECT_EQ(r, CacheResult::kMiss);
  WorldDesc hit = load_world_cached(world_, {}, &r);
  EXPECT_EQ(r, CacheResult::kHit);
  EXPECT_EQ(serialize_world(hit), parsed);
  EXPECT_DOUBLE_EQ(hit.geo.latitude_deg, 48.2);
  EXPECT_DOUBLE_EQ(hit.geo.heading_deg, 10);
  const auto& sensors = hit.models[0].links[0].nav_sensors;
  ASSERT_EQ(sensors.size(), 2u);
  EXPECT_EQ(sensors[0].kind, NavSensorDesc::kImu);
  EXPECT_EQ(sensors[0].scoped_name, "car::roof::imu");
  EXPECT_NEAR(sensors[0].pose.translation().y(), 0.2, 1e-12);
  EXPECT_DOUBLE_EQ(sensors[0].imu.update_rate, 50);
  EXPECT_DOUBLE_EQ(sensors[0].imu.angular_velocity[2].stddev, 0.01);
  EXPECT_DOUBLE_EQ(sensors[0].imu.angular_velocity[2].dynamic_bias_correlation_time, 400);
  EXPECT_EQ(sensors[1].kind, NavSensorDesc::kNavSat);
  EXPECT_DOUBLE_EQ(sensors[1].navsat.position_horizontal.stddev, 1.5);
}

TEST_F(CacheTest, ABadLidarNamesModelLinkAndSensor) {
  write(world_,
        "<?xml version='1.0'?><sdf version='1.7'><world name='w'>"
        "<model name='car'><link name='roof'><inertial><mass>1</mass></inertial>"
        "<sensor name='scanner' type='ray'><ray><scan><horizontal><samples>0</samples>"
        "</horizontal></scan><range><min>0.5</min><max>60</max></range></ray></sensor>"
        "</link></model></world></sdf>");
  try {
    load_world_cached(world_);
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(
                  "model 'car' link 'roof' sensor 'scanner': <lidar><scan><horizontal><samples>"),
              std::string::npos)
        << e.what();
  }
}

TEST_F(CacheTest, AChangedIncludedFileIsRebuilt) {
  CacheResult r;
  load_world_cached(world_, {}, &r);
  ASSERT_EQ(r, CacheResult::kMiss);
  write(dir_ / "models" / "crate" / "model.sdf", model_sdf(3.0));
  WorldDesc d = load_world_cached(world_, {}, &r);
  EXPECT_EQ(r, CacheResult::kStale);
  EXPECT_DOUBLE_EQ(d.models[0].links[0].collisions[0].shape.size.x(), 3.0);
  load_world_cached(world_, {}, &r);
  EXPECT_EQ(r, CacheResult::kHit);
}

TEST_F(CacheTest, ACorruptEntryIsIgnoredAndRebuilt) {
  CacheResult r;
  load_world_cached(world_, {}, &r);
  ASSERT_EQ(r, CacheResult::kMiss);
  int entries = 0;
  for (const auto& e : fs::directory_iterator(dir_ / "cache" / "world")) {
    ++entries;
    // Keep the header (dependencies) intact, cut the description short.
    fs::resize_file(e.path(), fs::file_size(e.path()) - 40);
  }
  ASSERT_EQ(entries, 1);
  WorldDesc d = load_world_cached(world_, {}, &r);
  EXPECT_EQ(r, CacheResult::kCorrupt);
  EXPECT_EQ(serialize_world(d), serialize_world(load_world(world_)));
  load_world_cached(world_, {}, &r);
  EXPECT_EQ(r, CacheResult::kHit);
  EXPECT_THROW(deserialize_world("CVWDESC2garbage"), std::runtime_error);
}

TEST_F(CacheTest, OffDisablesIt) {
  setenv("CONVOY_CACHE_DIR", "off", 1);
  CacheResult r;
  load_world_cached(world_, {}, &r);
  EXPECT_EQ(r, CacheResult::kDisabled);
  EXPECT_FALSE(fs::exists(dir_ / "cache"));
}

}  // namespace
}  // namespace convoy::world
