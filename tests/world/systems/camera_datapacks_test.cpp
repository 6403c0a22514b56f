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

}  // namespace
}  // namespace convoy::world
