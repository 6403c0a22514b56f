// The radar's view of a scene: objects and their velocities from moving instances, occlusion
// by rays into the LiDAR's Embree scene.
#include <gtest/gtest.h>

#include "lidar/lidar_scene.h"
#include "radar/radar_occlusion.h"
#include "radar/radar_targets.h"
#include "render/mesh.h"
#include "render/scene.h"

using namespace convoy;
using namespace convoy::radar;

namespace {

const SceneObject* find(const std::vector<SceneObject>& all, uint32_t id) {
  for (const auto& o : all)
    if (o.id == id) return &o;
  return nullptr;
}

}  // namespace

TEST(RadarTargets, BoxesAndVelocitiesOfMovingInstances) {
  render::Scene scene;
  const int box = scene.add_mesh(render::make_box(4, 2, 1.5f));
  const int car = scene.add_instance(box, {}, render::make_pose(10, 0, 0.75), 3, 1);
  scene.add_instance(box, {}, render::make_pose(30, 5, 0.75, 0, 0, 0.3), 4, 1);
  scene.add_instance(box, {}, render::make_pose(0, 0, -1), 0, 0);  // unlabelled: no object
  ObjectTracker t;
  t.track(scene, 0.0);
  auto objects = t.objects(scene);
  ASSERT_EQ(objects.size(), 2u);
  EXPECT_TRUE(objects[0].velocity_at(objects[0].centre()).isZero());  // seen once: standing
  EXPECT_NEAR(objects[0].size().x(), 4, 1e-5);
  // the car drives 0.1 m along x and turns 0.01 rad in 10 ms
  scene.set_pose(car, render::make_pose(10.1, 0, 0.75, 0, 0, 0.01));
  t.track(scene, 0.01);
  objects = t.objects(scene);
  const SceneObject* o = find(objects, 3);
  ASSERT_NE(o, nullptr);
  const Eigen::Vector3d v = o->velocity_at(Eigen::Vector3d(10.1, 0, 0.75));
  EXPECT_NEAR(v.x(), 10, 1e-6);
  EXPECT_NEAR(v.y(), 0, 1e-6);
  const Eigen::Vector3d nose = o->velocity_at(Eigen::Vector3d(10.1 + 2, 0, 0.75));
  EXPECT_NEAR(nose.y(), 2 * 1.0, 0.01);  // 1 rad/s about z, 2 m ahead
  EXPECT_TRUE(find(objects, 4)->velocity_at(find(objects, 4)->centre()).isZero());
  scene.set_visible(car, false);
  EXPECT_EQ(find(t.objects(scene), 3), nullptr);  // hidden: not an object
}

TEST(RadarOcclusion, ABoxBehindAnotherIsHidden) {
  render::Scene scene;
  const int box = scene.add_mesh(render::make_box(2, 2, 2));
  scene.add_instance(box, {}, render::make_pose(10, 0, 0), 1, 1);  // in front
  scene.add_instance(box, {}, render::make_pose(20, 0, 0), 2, 1);  // right behind it
  scene.add_instance(box, {}, render::make_pose(20, 8, 0), 3, 1);  // off to the side
  scene.add_instance(box, {}, render::make_pose(0, 0, 0), 4, 1);   // around the sensor
  lidar::LidarScene world(scene);
  ObjectTracker t;
  t.track(scene, 0);
  const auto objects = t.objects(scene);
  const Eigen::Vector3d origin(0, 0, 0);
  const Visibility front = visibility(world, origin, *find(objects, 1), 4);
  EXPECT_DOUBLE_EQ(front.fraction, 1);
  EXPECT_NEAR(front.range, 9, 1e-4);  // its near face
  EXPECT_DOUBLE_EQ(visibility(world, origin, *find(objects, 2), 4).fraction, 0);
  EXPECT_GT(visibility(world, origin, *find(objects, 3), 4).fraction, 0.5);
  // without passing through its own box the sensor sees nothing
  EXPECT_DOUBLE_EQ(visibility(world, origin, *find(objects, 1), 0).fraction, 0);
}
