// LiDAR benchmark (issue 27): the city_traffic world, its render::Scene built by the world
// engine's own code (CameraSensors), 100 car-sized boxes driving its routes as actors, and a
// roof LiDAR on a vehicle driving the ego's loop at 10 m/s. Prints
//   lidar 32x1024 real-time factor: R    (at 10 Hz: simulated s per wall s of scanning alone:
//   lidar 64x2048 real-time factor: R     LidarScene::update + LidarSensor::scan)
//   lidar range error p99 m: E           (noise off, against a double-precision brute-force
//                                         intersection of a subset of the same rays)
//
//   lidar_bench [--scans N] [--png docs/lidar_birds_eye.png [--png-time T]]
// --png: a bird's-eye view of one 64x2048 scan at simulated time T (s; default 30) coloured
// by class (birds_eye.h).
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "birds_eye.h"
#include "camera_sensors.h"
#include "lidar/lidar_scene.h"
#include "lidar/lidar_sensor.h"
#include "physics_world.h"
#include "range_check.h"
#include "world_cache.h"

using namespace convoy;

namespace {

const std::string kCity = CONVOY_REPO_DIR "/experiments/city_traffic";

struct Route {
  std::vector<double> x, y, s;  // polyline and arc length
  double length() const { return s.back(); }
  // position and heading at arc length `at` (wrapping), shifted `left` metres to the left
  void at(double at, double left, double* px, double* py, double* heading) const {
    at = std::fmod(at, length());
    if (at < 0) at += length();
    size_t i = 1;
    while (i + 1 < s.size() && s[i] < at) ++i;
    const double f = (at - s[i - 1]) / std::max(1e-9, s[i] - s[i - 1]);
    *heading = std::atan2(y[i] - y[i - 1], x[i] - x[i - 1]);
    *px = x[i - 1] + f * (x[i] - x[i - 1]) - left * std::sin(*heading);
    *py = y[i - 1] + f * (y[i] - y[i - 1]) + left * std::cos(*heading);
  }
};

Route load_route(const std::string& file) {
  std::ifstream in(file);
  if (!in) throw std::runtime_error(file + ": cannot read");
  Route r;
  std::string line;
  std::getline(in, line);  // x,y,heading
  while (std::getline(in, line)) {
    double x, y;
    if (std::sscanf(line.c_str(), "%lf,%lf", &x, &y) != 2) continue;
    r.s.push_back(r.x.empty() ? 0 : r.s.back() + std::hypot(x - r.x.back(), y - r.y.back()));
    r.x.push_back(x);
    r.y.push_back(y);
  }
  return r;
}

// A car-sized box (4.5 x 1.8 x 1.5 m, car paint) as an actor model, its frame on the ground.
world::ModelDesc box_car(int i) {
  world::ModelDesc m;
  m.name = "traffic_" + std::to_string(i);
  m.cls = "car";
  world::LinkDesc link;
  link.name = m.name + "::link";
  link.short_name = "link";
  world::VisualDesc v;
  v.name = "body";
  v.pose.translation() = Eigen::Vector3d(0, 0, 0.75);
  v.shape.kind = world::Shape::kBox;
  v.shape.size = Eigen::Vector3d(4.5, 1.8, 1.5);
  const float hue[5][3] = {{0.7f, 0.1f, 0.1f},
                           {0.1f, 0.2f, 0.6f},
                           {0.8f, 0.8f, 0.8f},
                           {0.05f, 0.05f, 0.05f},
                           {0.5f, 0.5f, 0.5f}};
  v.material.diffuse = v.material.ambient = {hue[i % 5][0], hue[i % 5][1], hue[i % 5][2], 1};
  v.material.specular = {0.45f, 0.45f, 0.45f, 1};
  v.material.has_material = true;
  link.visuals.push_back(v);
  m.links.push_back(link);
  return m;
}

struct Car {
  int actor;
  const Route* route;
  double s, left, speed;
};

struct City {
  world::WorldDesc desc;
  std::unique_ptr<world::PhysicsWorld> physics;
  std::unique_ptr<world::CameraSensors> cameras;
  std::vector<Route> routes;
  std::vector<Car> cars;
  std::vector<std::string> class_of;  // by ground-truth label
  render::Scene* scene = nullptr;

  City() {
    desc = world::load_world_cached(kCity + "/city_world.sdf");
    physics = std::make_unique<world::PhysicsWorld>(desc);
    cameras = std::make_unique<world::CameraSensors>(desc, *physics, 1);
    scene = &cameras->scene();
    class_of.push_back("");
    for (const auto& m : desc.models)
      class_of.push_back(world::is_ground(m) ? "" : world::class_of(m));
    // the world's own smart car stays parked at the start: hide it (our vehicle is the sensor's)
    for (size_t i = 0; i < scene->instances().size(); ++i) {
      const uint32_t id = scene->instances()[i].model_id;
      if (id > 0 && desc.models[id - 1].name == "smart_car")
        scene->set_visible(static_cast<int>(i), false);
    }
    for (const char* r :
         {"ego_route_loop", "ego_route", "ego_route_north", "ego_route_south", "ego_route_west"})
      routes.push_back(load_route(kCity + "/" + r + ".csv"));
    for (int i = 0; i < 100; ++i) {
      const Route* route = &routes[i % routes.size()];
      const int actor = cameras->add_actor(box_car(i), "car");
      if (actor < 0) throw std::runtime_error("the city world has no camera: no scene");
      cameras->set_actor_visible(actor, true);
      const double left = (i / 5) % 2 ? 3.5 : 0.0;  // own lane or the opposite one
      // the ones in our vehicle's lane keep its speed (10 m/s) and their distance to it
      const double speed = left > 0 ? -(8.0 + i % 5) : i % 5 == 0 ? 10.0 : 8.0 + i % 5;
      cars.push_back(
          {actor, route, route->length() * ((i / 5) * 0.05 + 0.013 * (i % 5)), left, speed});
      class_of.push_back("car");
    }
    move_traffic(0);
  }

  void move_traffic(double t) {
    for (const Car& c : cars) {
      double x, y, h;
      c.route->at(c.s + c.speed * t, c.left, &x, &y, &h);
      if (c.speed < 0) h += M_PI;
      Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
      pose.translation() = Eigen::Vector3d(x, y, 0);
      pose.linear() = Eigen::AngleAxisd(h, Eigen::Vector3d::UnitZ()).toRotationMatrix();
      cameras->set_actor_pose(c.actor, pose);
    }
  }

  // The roof sensor of a vehicle driving the loop at 10 m/s (1.9 m above the road).
  render::Pose sensor_pose(double t) const {
    double x, y, h;
    routes[0].at(20 + 10 * t, 0, &x, &y, &h);
    return render::make_pose(x, y, 1.9, 0, 0, h);
  }
};

lidar::LidarModel velodyne(int rings, int columns) {
  lidar::LidarModel m;
  m.horizontal = {columns, 1, -M_PI, M_PI * (1 - 2.0 / columns)};
  m.vertical = {rings, 1, -25 * M_PI / 180, 15 * M_PI / 180};
  m.range_min = 0.5;
  m.range_max = 120;
  m.update_rate = 10;
  return m;
}

// Real-time factor of `scans` scans at 10 Hz with the traffic moving between them; the range
// errors of every `check_every`th return of `checked` of the scans appended to `errors`.
double run(City& city, lidar::LidarScene& world, const lidar::LidarModel& model, int scans,
           std::vector<double>* errors, int checked, int check_every) {
  lidar::LidarSensor sensor(model);
  lidar::PointCloud cloud;
  double busy = 0;
  size_t points = 0;
  for (int k = 0; k < scans; ++k) {
    const double t = 0.1 * k;
    city.move_traffic(t);  // the world engine's work, not the LiDAR's
    const auto t0 = std::chrono::steady_clock::now();
    world.update(*city.scene);
    const render::Pose pose = city.sensor_pose(t);
    sensor.scan(world, pose, t, 1, {}, &cloud);
    busy += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    points += cloud.points.size();
    if (!errors || k >= checked) continue;
    lidar_bench::BruteForce exact(*city.scene);
    for (size_t i = k; i < cloud.points.size(); i += check_every) {
      const lidar::Point& p = cloud.points[i];
      const auto d = sensor.direction(p.ring, p.column);
      std::array<double, 3> o{pose[12], pose[13], pose[14]}, w{};
      for (int r = 0; r < 3; ++r) w[r] = pose[r] * d[0] + pose[4 + r] * d[1] + pose[8 + r] * d[2];
      const double n = std::sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
      for (double& c : w) c /= n;
      const double measured = std::sqrt(p.x * p.x + p.y * p.y + p.z * p.z);
      const double truth = exact.range(o, w, model.range_min, model.range_max);
      errors->push_back(truth < 0 ? 1e9 : std::abs(measured - truth));
    }
  }
  std::fprintf(stderr, "  %dx%d: %d scans, %.0f points/scan, %.2f ms/scan\n",
               model.vertical.samples, model.horizontal.samples, scans, double(points) / scans,
               1e3 * busy / scans);
  return 0.1 * scans / busy;
}

}  // namespace

int main(int argc, char** argv) {
  int scans = 100;
  std::string png;
  double png_time = 30;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--scans") && i + 1 < argc)
      scans = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--png") && i + 1 < argc)
      png = argv[++i];
    else if (!std::strcmp(argv[i], "--png-time") && i + 1 < argc)
      png_time = std::atof(argv[++i]);
    else {
      std::fprintf(stderr, "usage: lidar_bench [--scans N] [--png file.png]\n");
      return 2;
    }
  }
  try {
    City city;
    const auto t0 = std::chrono::steady_clock::now();
    lidar::LidarScene world(*city.scene);
    const double build =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::fprintf(stderr,
                 "city: %zu instances, %zu meshes, %zu triangles, Embree scene %.3f s, "
                 "16-wide packets: %s\n",
                 city.scene->instances().size(), world.mesh_count(), world.triangle_count(), build,
                 world.packets16() ? "yes" : "no");
    std::vector<double> errors;
    const double rtf32 = run(city, world, velodyne(32, 1024), scans, &errors, 5, 7);
    const double rtf64 = run(city, world, velodyne(64, 2048), scans, nullptr, 0, 1);
    std::sort(errors.begin(), errors.end());
    const double p99 = errors.empty() ? -1 : errors[errors.size() * 99 / 100];
    std::printf("lidar 32x1024 real-time factor: %.1f\n", rtf32);
    std::printf("lidar 64x2048 real-time factor: %.1f\n", rtf64);
    std::printf("lidar range error p99 m: %.5f\n", p99);
    std::fprintf(stderr, "  range check: %zu returns, max error %.5f m, %zu without a hit\n",
                 errors.size(), errors.empty() ? 0.0 : errors.back(),
                 static_cast<size_t>(std::count(errors.begin(), errors.end(), 1e9)));
    if (!png.empty()) {
      lidar::LidarSensor sensor(velodyne(64, 2048));
      lidar::PointCloud cloud;
      const double t = png_time;
      city.move_traffic(t);
      world.update(*city.scene);
      sensor.scan(world, city.sensor_pose(t), t, 1, {}, &cloud);
      lidar_bench::write_birds_eye(png, cloud, city.class_of);
      std::fprintf(stderr, "wrote %s (%zu points)\n", png.c_str(), cloud.points.size());
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "lidar_bench: %s\n", e.what());
    return 1;
  }
}
