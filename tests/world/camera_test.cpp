// Camera sensors of the world engine: SDF camera settings, the pinhole projection, Gazebo's
// noise, update_rate in simulated time, ground-truth boxes.
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>

#include "camera_sensors.h"
#include "convoy/datapacks.pb.h"
#include "datapack/blobs.h"

namespace convoy::world {
namespace {

const std::string kData = CONVOY_TEST_DATA_DIR;

struct Image {
  int w, h, depth;
  std::string bytes;
};

datapack::InlineBlobWriter blob_writer;

Image image_of(CameraSensors& cams, size_t i) {
  engine::DataPack dp;
  datapack::Builder out(&dp, blob_writer);
  cams.image_datapack(i, out);
  data::Camera c;
  EXPECT_TRUE(c.ParseFromString(dp.proto().data()));
  std::string bytes = c.image_blob()
                          ? std::string(datapack::inline_blob_reader().get(dp, c.image_blob() - 1))
                          : c.image_data();
  return {static_cast<int>(c.image_width()), static_cast<int>(c.image_height()),
          static_cast<int>(c.image_depth()), bytes};
}

class CameraTest : public ::testing::Test {
 protected:
  void SetUp() override {
    desc_ = load_world(kData + "/camera_world.sdf");
    physics_ = std::make_unique<PhysicsWorld>(desc_);
    cams_ = std::make_unique<CameraSensors>(desc_, *physics_, 42);
    cams_->update(0.0);
  }
  size_t index_of(const std::string& plugin) {
    for (size_t i = 0; i < cams_->count(); ++i)
      if (cams_->camera(i).plugin_name == plugin) return i;
    ADD_FAILURE() << plugin;
    return 0;
  }
  WorldDesc desc_;
  std::unique_ptr<PhysicsWorld> physics_;
  std::unique_ptr<CameraSensors> cams_;
};

TEST_F(CameraTest, SdfCameraSettingsAreHonoured) {
  ASSERT_EQ(cams_->count(), 2u);
  const CameraDesc& c = cams_->camera(index_of("noisy_camera"));
  EXPECT_EQ(c.width, 200);
  EXPECT_EQ(c.height, 150);
  EXPECT_DOUBLE_EQ(c.hfov, 1.0);
  EXPECT_DOUBLE_EQ(c.update_rate, 10);
  EXPECT_TRUE(c.noise);
  EXPECT_DOUBLE_EQ(c.noise_stddev, 0.05);
  EXPECT_EQ(c.scoped_name, "rig::noisy::cam");
  Image img = image_of(*cams_, index_of("noisy_camera"));
  EXPECT_EQ(img.w, 200);
  EXPECT_EQ(img.h, 150);
  EXPECT_EQ(img.depth, 3);
  EXPECT_EQ(img.bytes.size(), 200u * 150 * 3);
}

TEST_F(CameraTest, MeasuredNoiseMatchesTheConfiguredStddev) {
  Image img = image_of(*cams_, index_of("noisy_camera"));
  double sum = 0, sum2 = 0;
  for (unsigned char v : img.bytes) {
    sum += v;
    sum2 += static_cast<double>(v) * v;
  }
  double n = static_cast<double>(img.bytes.size());
  double mean = sum / n, stddev = std::sqrt(sum2 / n - mean * mean);
  EXPECT_NEAR(mean / 255.0, 0.5, 0.01);            // the grey wall
  EXPECT_NEAR(stddev / 255.0, 0.05, 0.05 * 0.05);  // within 5 % of 0.05
}

TEST_F(CameraTest, UpdateRateIsInSimulatedTime) {
  size_t noisy = index_of("noisy_camera"), clean = index_of("clean_camera");
  std::string first = image_of(*cams_, noisy).bytes;
  cams_->update(0.05);  // 10 Hz: not due yet
  EXPECT_EQ(image_of(*cams_, noisy).bytes, first);
  cams_->update(0.1);  // due: a new frame (new noise)
  EXPECT_NE(image_of(*cams_, noisy).bytes, first);
  (void)clean;
}

TEST_F(CameraTest, CubeLandsWhereThePinholeModelPutsIt) {
  size_t i = index_of("clean_camera");
  Image img = image_of(*cams_, i);
  // cube: x 3.5..4.5, y -0.5..0.5, z -0.5..0.5 relative to the camera; its near face at x=3.5
  double fx = (320 / 2.0) / std::tan(1.2 / 2);
  double half_w = fx * 0.5 / 3.5, half_h = fx * 0.5 / 3.5;
  int x_min = static_cast<int>(std::lround(160 - half_w)),
      x_max = static_cast<int>(std::lround(160 + half_w)) - 1;
  int y_min = static_cast<int>(std::lround(120 - half_h)),
      y_max = static_cast<int>(std::lround(120 + half_h)) - 1;
  auto red = [&](int x, int y) {
    return static_cast<unsigned char>(img.bytes[3 * (y * 320 + x)]) > 128;
  };
  int rx_min = 320, rx_max = -1, ry_min = 240, ry_max = -1;
  for (int y = 0; y < 240; ++y)
    for (int x = 0; x < 320; ++x)
      if (red(x, y)) {
        rx_min = std::min(rx_min, x);
        rx_max = std::max(rx_max, x);
        ry_min = std::min(ry_min, y);
        ry_max = std::max(ry_max, y);
      }
  EXPECT_NEAR(rx_min, x_min, 1);
  EXPECT_NEAR(rx_max, x_max, 1);
  EXPECT_NEAR(ry_min, y_min, 1);
  EXPECT_NEAR(ry_max, y_max, 1);

  engine::DataPack dp;
  datapack::Builder out(&dp, blob_writer);
  cams_->boxes_datapack(i, out);
  auto j = nlohmann::json::from_msgpack(dp.json_msgpack());
  ASSERT_EQ(j["boxes"].size(), 1u) << j.dump();
  const auto& b = j["boxes"][0];
  EXPECT_EQ(b["model"], "cube_7");
  EXPECT_EQ(b["class"], "cube");
  EXPECT_NEAR(b["x_min"].get<int>(), x_min, 1);
  EXPECT_NEAR(b["x_max"].get<int>(), x_max, 1);
  EXPECT_NEAR(b["y_min"].get<int>(), y_min, 1);
  EXPECT_NEAR(b["y_max"].get<int>(), y_max, 1);
}

TEST_F(CameraTest, DepthImageGivesTheDistanceToTheCube) {
  size_t i = index_of("clean_camera");
  engine::DataPack dp;
  datapack::Builder out(&dp, blob_writer);
  cams_->depth_datapack(i, out);
  auto j = nlohmann::json::from_msgpack(dp.json_msgpack());
  EXPECT_EQ(j["width"], 320);
  ASSERT_TRUE(j["depth"].is_binary());
  ASSERT_EQ(dp.blobs_size(), 1);
  std::string_view bytes = datapack::inline_blob_reader().get(dp, 0);
  ASSERT_EQ(bytes.size(), 320u * 240 * 4);
  float centre;
  std::memcpy(&centre, bytes.data() + 4 * (120 * 320 + 160), 4);
  EXPECT_NEAR(centre, 3.5, 0.01);
}

TEST(CameraClass, WithoutAnAnnotationTheClassIsTheNameStem) {
  EXPECT_EQ(class_of_name("pedestrian_3"), "pedestrian");
  EXPECT_EQ(class_of_name("car12"), "car");
  EXPECT_EQ(class_of_name("world::bus"), "bus");
}

TEST(CameraClass, ClassComesFromTheModelNotItsName) {
  WorldDesc desc = load_world(kData + "/class_world.sdf");
  ASSERT_EQ(desc.models.size(), 3u);
  EXPECT_EQ(desc.models[0].name, "hatchback_3");
  EXPECT_EQ(class_of(desc.models[0]), "car");
  EXPECT_EQ(class_of(desc.models[1]), "pedestrian");  // named "alice"
  EXPECT_EQ(class_of(desc.models[2]), "building");    // no annotation: building_7
}

TEST(CameraClass, AnUnknownClassIsAnErrorNamingFileAndModel) {
  try {
    load_world(kData + "/bad_class_world.sdf");
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    std::string m = e.what();
    EXPECT_NE(m.find("bad_class_world.sdf"), std::string::npos) << m;
    EXPECT_NE(m.find("model 'hatchback_1'"), std::string::npos) << m;
    EXPECT_NE(m.find("'hatchback' is not one of car"), std::string::npos) << m;
  }
}

}  // namespace
}  // namespace convoy::world
