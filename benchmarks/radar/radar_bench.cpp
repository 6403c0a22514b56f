// Radar benchmark (issue 27): the city_traffic world's render::Scene built by the world
// engine's own code (CameraSensors), 100 car-sized boxes driving its routes as actors (as
// benchmarks/lidar's), and a front radar (default parameters: 1.2 rad x 0.2 rad, 150 m,
// clutter 2) on a vehicle driving the ego's loop at 10 m/s, scanning at 20 Hz. Prints
//   radar real-time factor: R   (simulated s per wall s of the radar's own work per scan:
//                                tracking the objects, LidarScene::update, the occlusion rays,
//                                detection; the traffic's moves are the world's work)
//   radar returns per scan: N   (objects and clutter)
//
//   radar_bench [--scans N]
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "camera_sensors.h"
#include "lidar/lidar_scene.h"
#include "physics_world.h"
#include "radar/radar_detect.h"
#include "radar/radar_targets.h"
#include "radar/radar_view.h"
#include "world_cache.h"

using namespace convoy;

namespace {

const std::string kCity = CONVOY_REPO_DIR "/experiments/city_traffic";

struct Route {  // a polyline with its arc lengths
  std::vector<Eigen::Vector2d> p;
  std::vector<double> s;
  // position and heading at arc length `at` (wrapping), `left` metres to the left
  Eigen::Isometry3d at(double at, double left) const {
    at = std::fmod(at, s.back());
    if (at < 0) at += s.back();
    size_t i = 1;
    while (i + 1 < s.size() && s[i] < at) ++i;
    const Eigen::Vector2d d = p[i] - p[i - 1];
    const double f = (at - s[i - 1]) / std::max(1e-9, d.norm()), h = std::atan2(d.y(), d.x());
    const Eigen::Vector2d q = p[i - 1] + f * d + left * Eigen::Vector2d(-std::sin(h), std::cos(h));
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.translation() = Eigen::Vector3d(q.x(), q.y(), 0);
    pose.linear() = Eigen::AngleAxisd(h, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    return pose;
  }
};

Route load_route(const std::string& file) {
  std::ifstream in(file);
  if (!in) throw std::runtime_error(file + ": cannot read");
  Route r;
  std::string line;
  std::getline(in, line);  // header
  while (std::getline(in, line)) {
    double x, y;
    if (std::sscanf(line.c_str(), "%lf,%lf", &x, &y) != 2) continue;
    const Eigen::Vector2d q(x, y);
    r.s.push_back(r.p.empty() ? 0 : r.s.back() + (q - r.p.back()).norm());
    r.p.push_back(q);
  }
  return r;
}

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
  v.shape.size = Eigen::Vector3d(4.5, 1.8, 1.5);
  link.visuals.push_back(v);
  m.links.push_back(link);
  return m;
}

}  // namespace

int main(int argc, char** argv) {
  int scans = 200;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--scans") && i + 1 < argc) {
      scans = std::atoi(argv[++i]);
    } else {
      std::fprintf(stderr, "usage: radar_bench [--scans N]\n");
      return 2;
    }
  }
  try {
    const world::WorldDesc desc = world::load_world_cached(kCity + "/city_world.sdf");
    world::PhysicsWorld physics(desc);
    world::CameraSensors cameras(desc, physics, 1);
    render::Scene& scene = cameras.scene();
    uint32_t own = 0;  // the world's smart car: our radar's vehicle, hidden (it is elsewhere)
    for (size_t i = 0; i < scene.instances().size(); ++i) {
      const uint32_t id = scene.instances()[i].model_id;
      if (id > 0 && desc.models[id - 1].name == "smart_car") {
        scene.set_visible(static_cast<int>(i), false);
        own = id;
      }
    }
    std::vector<Route> routes;
    for (const char* r :
         {"ego_route_loop", "ego_route", "ego_route_north", "ego_route_south", "ego_route_west"})
      routes.push_back(load_route(kCity + "/" + r + ".csv"));
    struct Car {
      int actor;
      const Route* route;
      double s, left, speed;
    };
    std::vector<Car> cars;
    for (int i = 0; i < 100; ++i) {
      const Route* route = &routes[i % routes.size()];
      const int actor = cameras.add_actor(box_car(i), "car");
      if (actor < 0) throw std::runtime_error("the city world has no camera: no scene");
      cameras.set_actor_visible(actor, true);
      const double left = (i / 5) % 2 ? 3.5 : 0.0;
      const double speed = left > 0 ? -(8.0 + i % 5) : 8.0 + i % 5;
      cars.push_back(
          {actor, route, route->s.back() * ((i / 5) * 0.05 + 0.013 * (i % 5)), left, speed});
    }
    auto move = [&](double t) {
      for (const Car& c : cars) {
        Eigen::Isometry3d pose = c.route->at(c.s + c.speed * t, c.left);
        if (c.speed < 0)
          pose.linear() =
              pose.linear() * Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitZ()).toRotationMatrix();
        cameras.set_actor_pose(c.actor, pose);
      }
    };
    move(0);
    const auto t0 = std::chrono::steady_clock::now();
    lidar::LidarScene rays(scene);
    std::fprintf(stderr, "city: %zu instances, Embree scene %.3f s\n", scene.instances().size(),
                 std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    const radar::RadarParams params;
    radar::ObjectTracker objects;
    const double period = 0.05;  // 20 Hz
    double busy = 0;
    size_t returns = 0;
    std::map<std::string, size_t> by_class;
    for (int k = 0; k < scans; ++k) {
      const double t = period * k;
      move(t);
      const auto start = std::chrono::steady_clock::now();
      objects.track(scene, t);
      rays.update(scene);
      Eigen::Isometry3d pose = routes[0].at(20 + 10 * t, 0);
      pose.translation().z() = 0.5;
      const Eigen::Vector3d v = pose.linear() * Eigen::Vector3d(10, 0, 0);
      const auto targets =
          radar::visible_targets(params, rays, objects.objects(scene), pose, v, own,
                                 [&](uint32_t id) { return cameras.model_class(id); });
      const auto d = radar::detect(params, targets, pose.linear().transpose() * v, 1,
                                   static_cast<int64_t>(std::llround(t * 1e9)));
      busy += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      returns += d.size();
      for (const auto& r : d) ++by_class[r.id > 0 ? cameras.model_class(r.id) : "clutter"];
    }
    std::fprintf(stderr, "  %d scans, %.2f ms/scan; returns per scan:", scans, 1e3 * busy / scans);
    for (const auto& [cls, n] : by_class)
      std::fprintf(stderr, " %s %.2f", cls.c_str(), double(n) / scans);
    std::fprintf(stderr, "\n");
    std::printf("radar real-time factor: %.1f\n", period * scans / busy);
    std::printf("radar returns per scan: %.1f\n", double(returns) / scans);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "radar_bench: %s\n", e.what());
    return 1;
  }
}
