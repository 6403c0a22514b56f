// Camera datapacks (systems/camera_datapacks.h): each camera under its plugin's and its
// scoped name with depth, boxes and instances; unchanged until the camera renders again.
#include "systems/camera_datapacks.h"

#include "datapack/camera.h"
#include "test_world.h"

namespace convoy::world {
namespace {

using namespace testing;

TEST(WorldCameraDatapacks, EachCameraUnderBothNamesAndUnchangedUntilItRendersAgain) {
  auto world = make_world(data_file("camera_world.sdf"));
  auto& cameras = world->add<CameraDatapacks>();
  const auto provided = world->configure({{"Shadows", false}});
  const auto n = names(provided);
  for (const char* name : {"noisy_camera::cam", "rig::noisy::cam", "noisy_camera::cam::depth",
                           "noisy_camera::cam::boxes", "rig::clean::cam::instances"})
    EXPECT_NE(std::find(n.begin(), n.end(), name), n.end()) << name;
  EXPECT_EQ(n.size(), 2u * 2 * 4);  // 2 cameras, 2 names, 4 datapacks
  EXPECT_FALSE(cameras.unchanged("noisy_camera::cam"));
  const auto image = datapack::read_camera(Got(*world, "noisy_camera::cam").view());
  EXPECT_EQ(image.width, 200u);
  EXPECT_EQ(image.height, 150u);
  EXPECT_TRUE(cameras.unchanged("noisy_camera::cam"));
  EXPECT_FALSE(world->unchanged("rig::noisy::cam"));  // not sent under this name yet
  world->step(50 * kMs);                              // 10 Hz: not due yet
  EXPECT_TRUE(world->unchanged("noisy_camera::cam"));
  world->step(50 * kMs);
  EXPECT_FALSE(world->unchanged("noisy_camera::cam"));
  // The clean camera sees the red cube 4 m ahead among its boxes.
  const nlohmann::json got = Got(*world, "clean_camera::cam::boxes").json();
  ASSERT_EQ(got["boxes"].size(), 1u);
  EXPECT_EQ(got["boxes"][0]["model"], "cube_7");
  EXPECT_EQ(got["boxes"][0]["class"], "cube");
  EXPECT_NEAR(got["boxes"][0]["distance"].get<double>(), 4.0, 0.05);  // its centre
}

// A reset makes the world again, taking the renderer and the noise tables over from the last
// cameras: the frames after it are those of the first run, noise included, bit for bit.
TEST(WorldCameraDatapacks, AResetRendersTheSameNoisyFramesAgain) {
  auto world = make_world(data_file("camera_world.sdf"));
  world->add<CameraDatapacks>();
  world->configure({{"Shadows", false}});
  auto run = [&] {
    std::vector<std::string> frames;
    for (int i = 0; i < 3; ++i) {
      frames.emplace_back(datapack::read_camera(Got(*world, "noisy_camera::cam").view()).pixels);
      world->step(100 * kMs);
    }
    return frames;
  };
  const auto first = run();
  EXPECT_NE(first[0], first[1]);  // the noise differs from frame to frame
  world->reset();
  EXPECT_EQ(run(), first);
  world->reset();
  EXPECT_EQ(run(), first);
}

// A segmentation camera 4 m from a barrier cube (class label 12) and a car (label 1) beside
// it, in front of a building wall; the ground plane, unclassed, is 0.
const char* kSegmentationWorld = R"(<?xml version="1.0"?>
<sdf version="1.7"><world name="w">
  <scene><ambient>1 1 1 1</ambient><background>0 0 0 1</background></scene>
  <model name="building_1"><static>true</static><pose>8 0 0 0 0 0</pose><link name="l">
    <visual name="v"><geometry><box><size>0.1 40 40</size></box></geometry></visual></link></model>
  <model name="crate"><static>true</static><pose>4 -0.8 0 0 0 0</pose><link name="l">
    <visual name="v"><geometry><box><size>1 1 1</size></box></geometry></visual></link>
    <plugin name="convoy_class" filename="convoy_class"><class>barrier</class></plugin></model>
  <model name="car_3"><static>true</static><pose>4 0.8 0 0 0 0</pose><link name="l">
    <visual name="v"><geometry><box><size>1 1 1</size></box></geometry></visual></link></model>
  <model name="rig"><static>true</static><link name="l">
    <sensor name="seg" type="segmentation_camera">
      <camera><segmentation_type>%TYPE%</segmentation_type><horizontal_fov>1.2</horizontal_fov>
        <image><width>64</width><height>48</height></image>
        <clip><near>0.1</near><far>50</far></clip></camera>
    </sensor></link></model>
</world></sdf>)";

std::unique_ptr<WorldSystems> segmentation_world(const std::string& type) {
  std::string sdf = kSegmentationWorld;
  sdf.replace(sdf.find("%TYPE%"), 6, type);
  return make_world(write_world(sdf));
}

TEST(WorldCameraDatapacks, SegmentationCameraLabelsEachPixelWithItsClass) {
  auto world = segmentation_world("semantic");
  world->add<CameraDatapacks>();
  const auto n = names(world->configure({{"Shadows", false}}));
  EXPECT_NE(std::find(n.begin(), n.end(), "rig::l::seg::colored"), n.end());
  const auto labels = datapack::read_camera(Got(*world, "rig::l::seg").view());
  ASSERT_EQ(labels.width, 64u);
  auto at = [&](const datapack::CameraImage& img, uint32_t x, uint32_t y, int c) {
    return static_cast<uint8_t>(img.pixels[3 * (y * img.width + x) + c]);
  };
  // The camera looks along +x: the crate (y = -0.8, right) left of the image's centre...
  EXPECT_EQ(at(labels, 40, 24, 0), class_label("barrier"));
  EXPECT_EQ(at(labels, 23, 24, 0), class_label("car"));
  EXPECT_EQ(at(labels, 32, 5, 0), class_label("building"));
  EXPECT_EQ(at(labels, 40, 24, 1), at(labels, 40, 24, 0));  // semantic: R = G = B
  const auto colored = datapack::read_camera(Got(*world, "rig::l::seg::colored").view());
  EXPECT_EQ(at(colored, 23, 24, 2), 142);  // car: Cityscapes' (0, 0, 142)
}

TEST(WorldCameraDatapacks, PanopticCarriesTheInstance) {
  auto world = segmentation_world("panoptic");
  world->add<CameraDatapacks>();
  world->configure({{"Shadows", false}});
  const auto labels = datapack::read_camera(Got(*world, "rig::l::seg").view());
  const auto* crate =
      reinterpret_cast<const uint8_t*>(&labels.pixels[3 * (24 * labels.width + 40)]);
  const auto* car = reinterpret_cast<const uint8_t*>(&labels.pixels[3 * (24 * labels.width + 23)]);
  EXPECT_EQ(crate[0], class_label("barrier"));
  EXPECT_EQ(car[0], class_label("car"));
  EXPECT_EQ(crate[1] * 256 + crate[2], 2);  // the world's second model
  EXPECT_EQ(car[1] * 256 + car[2], 3);
}

TEST(WorldCameraDatapacks, UnknownSegmentationTypeNamesTheSensor) {
  try {
    segmentation_world("instance");
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("model 'rig' link 'l' sensor 'seg': <segmentation_type>"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace convoy::world
