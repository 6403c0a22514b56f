// LidarScene + LidarSensor against analytic geometry: ranges, ray layout, labels, moving and
// hidden instances, determinism, noise, intensity and weather.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

#include "lidar/lidar_scene.h"
#include "lidar/lidar_sensor.h"
#include "lidar/reflectivity.h"
#include "render/scene.h"

using namespace convoy;
using namespace convoy::lidar;

namespace {

LidarModel model(int rings, int columns, double el_min, double el_max, double az_min = -M_PI,
                 double az_max = M_PI) {
  LidarModel m;
  m.horizontal = {columns, 1, az_min, az_max};
  m.vertical = {rings, 1, el_min, el_max};
  m.range_min = 0.3;
  m.range_max = 150;
  return m;
}

render::Material colour(float r, float g, float b, float spec = 0) {
  render::Material m;
  m.diffuse = m.ambient = {r, g, b, 1};
  m.specular = {spec, spec, spec, 1};
  return m;
}

PointCloud scan(LidarSensor& s, const LidarScene& scene, const render::Pose& pose,
                uint64_t seed = 1, const LidarWeather& w = {}, double t = 0) {
  PointCloud c;
  s.scan(scene, pose, t, seed, w, &c);
  return c;
}

double range(const Point& p) { return std::sqrt(p.x * p.x + p.y * p.y + p.z * p.z); }

}  // namespace

TEST(LidarScan, GroundPlaneRangesWithinOneCentimetre) {
  render::Scene scene;
  scene.add_instance(scene.add_mesh(render::make_plane(400, 400)), colour(0.2f, 0.2f, 0.2f),
                     render::make_pose(3, -2, 0));
  LidarScene world(scene);
  LidarSensor sensor(model(16, 720, -0.4, -0.05));
  const double h = 1.8;
  // A tilted, turned sensor at a place far from the origin (float precision).
  const render::Pose pose = render::make_pose(120, 80, h, 0, 0, 0.7);
  PointCloud c = scan(sensor, world, pose);
  ASSERT_EQ(c.points.size(), static_cast<size_t>(16 * 720));
  std::vector<double> err;
  for (const Point& p : c.points) {
    const double el = sensor.model().vertical.angle(p.ring);
    err.push_back(std::abs(range(p) - h / std::sin(-el)));
  }
  std::sort(err.begin(), err.end());
  EXPECT_LE(err[err.size() * 99 / 100], 0.01);
  EXPECT_LE(err.back(), 0.01);
}

TEST(LidarScan, BoxFaceAtKnownDistance) {
  render::Scene scene;
  // A 2 m cube whose near face is at x = 10.
  scene.add_instance(scene.add_mesh(render::make_box(2, 2, 2)), colour(0.5f, 0.5f, 0.5f),
                     render::make_pose(11, 0, 1), 7, 3);
  LidarScene world(scene);
  LidarSensor sensor(model(1, 201, 0, 0, -0.3, 0.3));
  PointCloud c = scan(sensor, world, render::make_pose(0, 0, 1));
  int on_face = 0;
  for (const Point& p : c.points) {
    const double az = sensor.model().horizontal.angle(p.column);
    if (std::abs(10 * std::tan(az)) > 0.99) continue;  // near the edges
    EXPECT_NEAR(range(p), 10 / std::cos(az), 0.005);
    EXPECT_NEAR(p.x, 10, 0.005);
    ++on_face;
  }
  EXPECT_GT(on_face, 50);
  // rays past the box's sides return nothing
  for (const Point& p : c.points) EXPECT_LE(std::abs(p.y), 1.001);
}

TEST(LidarScan, RingAndColumnLayoutMatchesModel) {
  render::Scene scene;
  // Inside a big box: every ray returns (Embree hits back faces too).
  scene.add_instance(scene.add_mesh(render::make_box(60, 60, 60)), colour(0.5f, 0.5f, 0.5f),
                     render::identity_pose());
  LidarScene world(scene);
  LidarSensor sensor(model(32, 1024, -0.4363, 0.2618));
  PointCloud c = scan(sensor, world, render::identity_pose());
  EXPECT_EQ(c.rings, 32);
  EXPECT_EQ(c.columns, 1024);
  ASSERT_EQ(c.points.size(), static_cast<size_t>(32 * 1024));
  for (size_t i = 0; i < c.points.size(); ++i) {
    const Point& p = c.points[i];
    ASSERT_EQ(p.ring, i / 1024);
    ASSERT_EQ(p.column, i % 1024);
    const double el = std::asin(p.z / range(p));
    const double az = std::atan2(p.y, p.x);
    ASSERT_NEAR(el, sensor.model().vertical.angle(p.ring), 1e-5);
    double daz = std::remainder(az - sensor.model().horizontal.angle(p.column), 2 * M_PI);
    ASSERT_NEAR(daz, 0, 1e-5);
  }
  // ring 0 is the lowest
  EXPECT_LT(c.points.front().z, c.points.back().z);
}

TEST(LidarScan, LabelsComeFromTheInstance) {
  render::Scene scene;
  const int box = scene.add_mesh(render::make_box(2, 2, 2));
  scene.add_instance(scene.add_mesh(render::make_plane(200, 200)), colour(0.2f, 0.2f, 0.2f),
                     render::identity_pose());  // ground: no label
  scene.add_instance(box, colour(0.8f, 0.1f, 0.1f, 0.45f), render::make_pose(10, 0, 1), 5, 1);
  scene.add_instance(box, colour(0.1f, 0.1f, 0.8f, 0.45f), render::make_pose(-10, 0, 1), 6, 2);
  LidarScene world(scene);
  LidarSensor sensor(model(8, 360, -0.3, 0.05));
  PointCloud c = scan(sensor, world, render::make_pose(0, 0, 1.5));
  int front = 0, back = 0;
  for (const Point& p : c.points) {
    if (p.z < -1.45) {  // the ground
      EXPECT_EQ(p.instance, 0u);
      continue;
    }
    if (p.x > 8.9 && p.x < 9.1 && std::abs(p.y) < 0.9) {
      EXPECT_EQ(p.instance, 5u);
      EXPECT_EQ(p.label, 1u);
      ++front;
    } else if (p.x < -8.9 && p.x > -9.1 && std::abs(p.y) < 0.9) {
      EXPECT_EQ(p.instance, 6u);
      EXPECT_EQ(p.label, 2u);
      ++back;
    }
  }
  EXPECT_GT(front, 10);
  EXPECT_GT(back, 10);
}

TEST(LidarScan, MovedInstanceMovesItsReturnsAndHiddenOnesVanish) {
  render::Scene scene;
  const int car =
      scene.add_instance(scene.add_mesh(render::make_box(4, 2, 1.5)),
                         colour(0.5f, 0.5f, 0.5f, 0.45f), render::make_pose(20, 0, 0.75), 9, 1);
  LidarScene world(scene);
  LidarSensor sensor(model(4, 360, -0.05, 0.05, -0.5, 0.5));
  auto nearest_x = [&](const PointCloud& c) {
    double x = 1e9;
    for (const Point& p : c.points)
      if (p.instance == 9) x = std::min<double>(x, p.x);
    return x;
  };
  const render::Pose sensor_pose = render::make_pose(0, 0, 0.75);
  EXPECT_NEAR(nearest_x(scan(sensor, world, sensor_pose)), 18, 0.005);
  scene.set_pose(car, render::make_pose(30, 0, 0.75));
  EXPECT_EQ(world.update(scene), 1);
  EXPECT_EQ(world.update(scene), 0);  // nothing changed since
  EXPECT_NEAR(nearest_x(scan(sensor, world, sensor_pose)), 28, 0.005);
  scene.set_visible(car, false);
  world.update(scene);
  EXPECT_TRUE(scan(sensor, world, sensor_pose).points.empty());
  scene.set_visible(car, true);
  // an instance added later is picked up
  scene.add_instance(scene.add_mesh(render::make_box(1, 1, 1)), colour(0.5f, 0.5f, 0.5f),
                     render::make_pose(10, 0, 0.75), 11, 4);
  world.update(scene);
  EXPECT_NEAR(nearest_x(scan(sensor, world, sensor_pose)), 1e9, 1);
  bool small = false;
  for (const Point& p : scan(sensor, world, sensor_pose).points) small |= p.instance == 11;
  EXPECT_TRUE(small);
  render::Scene other;
  EXPECT_THROW(world.update(other), std::invalid_argument);
}

TEST(LidarScan, SameSeedSameCloudBitForBit) {
  render::Scene scene;
  scene.add_instance(scene.add_mesh(render::make_plane(400, 400)), colour(0.2f, 0.2f, 0.2f),
                     render::identity_pose());
  scene.add_instance(scene.add_mesh(render::make_box(4, 2, 1.5)), colour(0.5f, 0.5f, 0.5f, 0.45f),
                     render::make_pose(12, 3, 0.75), 3, 1);
  LidarScene world(scene);
  LidarModel m = model(32, 1024, -0.4, 0.2);
  m.gaussian_noise = true;
  m.noise_stddev = 0.02;
  LidarSensor sensor(m);
  LidarWeather rain;
  rain.precipitation = 0.8f;
  rain.visibility = 300;
  const render::Pose pose = render::make_pose(0, 0, 1.8);
  PointCloud a = scan(sensor, world, pose, 42, rain, 1.5);
  PointCloud b = scan(sensor, world, pose, 42, rain, 1.5);
  ASSERT_EQ(a.points.size(), b.points.size());
  EXPECT_EQ(std::memcmp(a.points.data(), b.points.data(), a.points.size() * sizeof(Point)), 0);
  // another sensor object (another split between the threads) gives the same
  LidarSensor again(m);
  PointCloud c = scan(again, world, pose, 42, rain, 1.5);
  ASSERT_EQ(a.points.size(), c.points.size());
  EXPECT_EQ(std::memcmp(a.points.data(), c.points.data(), a.points.size() * sizeof(Point)), 0);
  PointCloud d = scan(sensor, world, pose, 43, rain, 1.5);
  EXPECT_FALSE(d.points.size() == a.points.size() &&
               std::memcmp(a.points.data(), d.points.data(), a.points.size() * sizeof(Point)) == 0);
}

TEST(LidarScan, GaussianNoiseHasTheModelsSpread) {
  render::Scene scene;
  scene.add_instance(scene.add_mesh(render::make_box(2, 200, 200)), colour(0.5f, 0.5f, 0.5f),
                     render::make_pose(21, 0, 0));  // a wall at x = 20
  LidarScene world(scene);
  LidarModel m = model(64, 512, -0.3, 0.3, -0.3, 0.3);
  m.gaussian_noise = true;
  m.noise_mean = 0.01;
  m.noise_stddev = 0.05;
  LidarSensor sensor(m);
  PointCloud c = scan(sensor, world, render::identity_pose(), 7);
  double sum = 0, sum2 = 0;
  for (const Point& p : c.points) {
    const double e = p.x - 20;  // range error along the ray, scaled by cos: compare in x/cos
    const double r = range(p), err = r - 20 * r / p.x;
    (void)e;
    sum += err;
    sum2 += err * err;
  }
  const double n = c.points.size(), mean = sum / n;
  EXPECT_NEAR(mean, 0.01, 0.003);
  EXPECT_NEAR(std::sqrt(sum2 / n - mean * mean), 0.05, 0.003);
}

TEST(LidarScan, IntensityFollowsMaterialAndIncidence) {
  const render::Rgba none{1, 1, 1, 1};
  const float asphalt = reflectivity(colour(0.22f, 0.22f, 0.23f, 0.05f), none);
  const float marking = reflectivity(colour(0.95f, 0.95f, 0.95f, 0.2f), none);
  render::Material glass = colour(0.08f, 0.1f, 0.125f, 0.55f);
  glass.shininess = 90;
  const float leaves = reflectivity(colour(0.27f, 0.45f, 0.13f, 0.05f), none);
  const float paint = reflectivity(colour(0.07f, 0.18f, 0.48f, 0.45f), none);
  EXPECT_EQ(surface_kind(glass, none), SurfaceKind::kGlass);
  EXPECT_LT(reflectivity(glass, none), asphalt);
  EXPECT_LT(asphalt, 0.15f);
  EXPECT_GT(marking, 0.8f);
  EXPECT_GT(leaves, asphalt);
  EXPECT_GT(paint, leaves);
  EXPECT_LT(paint, marking);

  // cos(incidence): the ground seen steeply returns more than at a grazing angle
  render::Scene scene;
  scene.add_instance(scene.add_mesh(render::make_plane(400, 400)), colour(0.5f, 0.5f, 0.5f),
                     render::identity_pose());
  LidarScene world(scene);
  LidarSensor sensor(model(2, 8, -1.2, -0.1));
  PointCloud c = scan(sensor, world, render::make_pose(0, 0, 2));
  ASSERT_EQ(c.points.size(), 16u);
  const float r = world.instances()[0].reflectivity;
  EXPECT_NEAR(c.points[0].intensity, r * std::sin(1.2), 1e-4);
  EXPECT_NEAR(c.points[8].intensity, r * std::sin(0.1), 1e-4);
}

TEST(LidarScan, FogDropsFarReturnsAndRainAddsNearOnes) {
  render::Scene scene;
  scene.add_instance(scene.add_mesh(render::make_plane(1000, 1000)), colour(0.5f, 0.5f, 0.5f),
                     render::identity_pose());
  LidarScene world(scene);
  LidarSensor sensor(model(32, 1024, -0.4, -0.01));
  const render::Pose pose = render::make_pose(0, 0, 2);
  PointCloud clear = scan(sensor, world, pose);
  LidarWeather fog;
  fog.visibility = 60;
  PointCloud foggy = scan(sensor, world, pose, 1, fog);
  double clear_max = 0, fog_max = 0, clear_i = 0, fog_i = 0;
  for (const Point& p : clear.points) clear_max = std::max(clear_max, range(p));
  for (const Point& p : foggy.points)
    if (!(p.flags & Point::kSpurious)) fog_max = std::max(fog_max, range(p));
  EXPECT_GT(clear_max, 85);  // ring 30: 2 m / sin(0.0226) = 88 m
  EXPECT_LT(fog_max, 40);    // about half the visibility at most
  EXPECT_LT(foggy.points.size(), clear.points.size());
  for (size_t i = 0; i < 1024; ++i) clear_i += clear.points[i].intensity;  // ring 0: ~5 m
  for (const Point& p : foggy.points)
    if (p.ring == 0 && !(p.flags & Point::kSpurious)) fog_i += p.intensity;
  EXPECT_LT(fog_i, clear_i);

  LidarWeather rain;
  rain.precipitation = 1;
  PointCloud rainy = scan(sensor, world, pose, 1, rain);
  int spurious = 0;
  for (const Point& p : rainy.points)
    if (p.flags & Point::kSpurious) {
      ++spurious;
      EXPECT_EQ(p.instance, 0u);
      EXPECT_LT(range(p), 40);
    }
  EXPECT_GT(spurious, 32 * 1024 * 0.002);
  EXPECT_LT(spurious, 32 * 1024 * 0.006);
  for (const Point& p : clear.points) EXPECT_EQ(p.flags, 0u);
}
