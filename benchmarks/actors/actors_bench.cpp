// The world engine's cost per actor: the city world (the ego's 30 Hz camera, 736x480) with N
// road users as actors (systems/road_user_actors.h), all of them posed every 20 ms engine step
// from one RoadUsers datapack (as pool_tf.py hands the pool's to the world engine, here at the
// engine's rate: an upper bound), the camera's image and ground-truth boxes asked for after
// every step (as camera_tf.py and truth_tf.py do). Three quarters of the road users are cars
// (sedan, hatchback, suv, van) in rows either side of the ego's, a quarter walkers (animated)
// on rows between them, all moving; the ego stands.
//
// Prints, for each N: the mean engine step (set_datapack + step + datapacks) without and with
// the camera, the camera's frames/s in that loop, the ground-truth boxes per frame, and the
// cost per actor against N = 0. No assertion: figures for docs/benchmarks.md.
//
// --track: instead, the ego launched at 8 m/s into a standing car 25 m ahead among the N road
// users; prints a hash of the ego's base_link poses at every step (bit-identical before and
// after a change of the actors' physics) and where it ended.
//
//   build/benchmarks/actors_bench [--n 0,100,390,1000] [--steps 150]
//                                 [--frame N:out.ppm] [--world city_world.sdf] [--track]
//                                 [--camera-only]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <fstream>
#include <memory>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "convoy/road_users.pb.h"
#include "datapack/blobs.h"
#include "datapack/camera.h"
#include "datapack/json.h"
#include "datapack/proto.h"
#include "render/image_io.h"
#include "systems/camera_datapacks.h"
#include "systems/contacts.h"
#include "systems/road_user_actors.h"
#include "world_systems.h"

using namespace convoy;
using namespace convoy::world;

namespace {

constexpr double kEgoX = -150, kEgoY = -1.75;  // city_world.sdf's smart car
constexpr double kSpacing = 14;                // m between road users in a row, and rows
constexpr int64_t kStepNs = 20'000'000;

struct Options {
  std::vector<int> counts{0, 100, 390, 1000};
  int steps = 150;
  int warmup = 25;
  int frame_n = -1;
  bool track = false;
  bool camera_only = false;  // (for perf: skip the runs without the camera)
  std::string frame_path;
  std::string world = CONVOY_REPO_DIR "/experiments/city_traffic/city_world.sdf";
};

// A road user's place at t = 0: row and column of a grid around the ego, its rows of cars
// (heading east on even rows, west on odd) and of walkers between them. No row on the ego's.
struct Slot {
  double x0, y;
  bool walker, west;
  int model;
};

std::vector<Slot> layout(int n) {
  std::vector<Slot> out;
  const int k = static_cast<int>(std::ceil(std::sqrt(n))) + 2;
  for (int row = 0; static_cast<int>(out.size()) < n; ++row) {
    // Rows alternate either side of the ego: +1, -1, +2, -2... (half rows: walkers)
    const int half = row / 2 + 1, side = row % 2 ? -1 : 1;
    const double y = kEgoY + side * half * kSpacing / 2;
    const bool walker = half % 2 == 0;
    for (int col = 0; col < k && static_cast<int>(out.size()) < n; ++col) {
      const double x = kEgoX + (col - k / 2) * kSpacing + (walker ? kSpacing / 2 : 0);
      out.push_back({x, y, walker, (half / 2) % 2 == 1, static_cast<int>(out.size()) % 4});
    }
  }
  return out;
}

void fill(const std::vector<Slot>& slots, double t, bool parked, data::RoadUsers* users) {
  static const char* kModels[] = {"sedan", "hatchback", "suv", "van"};
  const int k = static_cast<int>(std::ceil(std::sqrt(slots.size()))) + 2;
  const double extent = k * kSpacing, left = kEgoX - (k / 2) * kSpacing - kSpacing / 2;
  users->Clear();
  for (size_t i = 0; i < slots.size(); ++i) {
    const Slot& s = slots[i];
    const double v = s.walker ? 1.4 : 8.0, dir = s.west ? -1 : 1;
    double x = s.x0 + dir * v * t - left;
    x = left + (x - std::floor(x / extent) * extent);
    data::RoadUser* u = users->add_users();
    u->set_id("pool/" + std::to_string(i));
    u->set_category(s.walker ? "pedestrian" : "car");
    u->set_model(s.walker ? "walker" : kModels[s.model]);
    u->set_x(x);
    u->set_y(s.y);
    u->set_yaw(s.west ? std::numbers::pi : 0);
    u->set_speed(v);
    if (s.walker) u->set_walk_phase(std::fmod(t * 0.9 + 0.1 * i, 1.0));
  }
  if (!parked) return;
  data::RoadUser* u = users->add_users();
  u->set_id("parked");
  u->set_category("car");
  u->set_x(kEgoX + 25);
  u->set_y(kEgoY);
}

class Datapack {
 public:
  explicit Datapack(const std::string& name) { dp_.mutable_id()->set_name(name); }
  datapack::Builder builder() { return datapack::Builder(&dp_, blobs_); }
  datapack::View view() const { return datapack::View(dp_, datapack::inline_blob_reader()); }
  void clear() { dp_.clear_payload(); }

 private:
  engine::DataPack dp_;
  datapack::InlineBlobWriter blobs_;
};

// The ego's track: a hash of its base_link's pose at every step (FNV-1a of the doubles).
void track(const Options& o, int n) {
  WorldSystems world(load_world(o.world), /*seed=*/7, "gazebo");
  world.add<RoadUserActors>();
  world.add<Contacts>();
  world.configure(nlohmann::json::object());
  world.physics().set_model_velocity("smart_car", Eigen::Vector3d(8, 0, 0));
  const int link = world.physics().link_index("smart_car::base_link");
  const std::vector<Slot> slots = layout(n);
  data::RoadUsers users;
  Datapack in("pool_users");
  uint64_t hash = 1469598103934665603ull;
  LinkState s;
  for (int step = 0; step < o.warmup + o.steps; ++step) {
    fill(slots, step * kStepNs * 1e-9, true, &users);
    in.clear();
    auto b = in.builder();
    datapack::write_proto(b, users);
    world.set_datapack(in.view());
    world.step(kStepNs);
    s = world.physics().link_state(link);
    const double v[7] = {s.position.x(), s.position.y(), s.position.z(), s.rotation.w(),
                         s.rotation.x(), s.rotation.y(), s.rotation.z()};
    const auto* bytes = reinterpret_cast<const unsigned char*>(v);
    for (size_t k = 0; k < sizeof v; ++k) hash = (hash ^ bytes[k]) * 1099511628211ull;
  }
  std::printf("track with %d road users: hash %016llx, ego at (%.6f, %.6f)\n", n,
              static_cast<unsigned long long>(hash), s.position.x(), s.position.y());
}

// The process's CPU time (every thread: the rasteriser's too), seconds.
double cpu_s() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

struct Result {
  double step_ms = 0, cpu_ms = 0, frames_per_s = 0, boxes = 0;
  uint64_t frames = 0;
};

Result run(const Options& o, int n, bool camera, bool dump) {
  WorldSystems world(load_world(o.world), /*seed=*/7, "gazebo");
  world.add<RoadUserActors>();
  world.add<CameraDatapacks>();
  world.add<Contacts>();
  const auto provided = world.configure(nlohmann::json::object());
  const std::string image = provided.at(0).name, boxes = image + "::boxes";
  const std::vector<Slot> slots = layout(n);
  data::RoadUsers users;
  Datapack in("pool_users"), out_image(image), out_boxes(boxes);
  Result r;
  double boxes_total = 0;
  uint64_t last_frames = 0;
  std::chrono::steady_clock::time_point t0;
  double c0 = 0;
  for (int step = 0; step < o.warmup + o.steps; ++step) {
    if (step == o.warmup) t0 = std::chrono::steady_clock::now(), c0 = cpu_s();
    fill(slots, step * kStepNs * 1e-9, false, &users);
    in.clear();
    {
      auto b = in.builder();
      datapack::write_proto(b, users);
    }
    if (n > 0) world.set_datapack(in.view());
    world.step(kStepNs);
    if (!camera) continue;
    out_image.clear();
    out_boxes.clear();
    auto bi = out_image.builder();
    world.get_datapack(image, bi);
    auto bb = out_boxes.builder();
    world.get_datapack(boxes, bb);
    if (step >= o.warmup && world.cameras().frames(0) != last_frames)
      boxes_total += datapack::read_json(out_boxes.view())["boxes"].size();
    last_frames = world.cameras().frames(0);
  }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.step_ms = 1e3 * wall / o.steps;
  r.cpu_ms = 1e3 * (cpu_s() - c0) / o.steps;
  if (camera) {
    // Frames in the measured steps: the camera renders every 1/30 s of simulated time.
    r.frames = static_cast<uint64_t>(std::lround(o.steps * kStepNs * 1e-9 * 30));
    r.frames_per_s = r.frames / wall;
    r.boxes = boxes_total / static_cast<double>(r.frames);
  }
  if (dump) {
    const auto img = datapack::read_camera(out_image.view());
    render::write_ppm(o.frame_path, img.width, img.height,
                      reinterpret_cast<const uint8_t*>(img.pixels.data()));
    std::printf("frame with %d road users: %s\n", n, o.frame_path.c_str());
  }
  return r;
}

std::string first_line(const char* file, const char* key) {
  std::ifstream in(file);
  std::string line;
  while (std::getline(in, line))
    if (line.rfind(key, 0) == 0) return line.substr(line.find(':') + 2);
  return "?";
}

std::string loadavg() {
  std::ifstream in("/proc/loadavg");
  std::string a, b, c;
  in >> a >> b >> c;
  return a + " " + b + " " + c;
}

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) throw std::runtime_error(arg + " needs a value");
      return argv[++i];
    };
    if (arg == "--n") {
      o.counts.clear();
      std::stringstream ss(value());
      for (std::string item; std::getline(ss, item, ',');) o.counts.push_back(std::stoi(item));
    } else if (arg == "--steps") {
      o.steps = std::stoi(value());
    } else if (arg == "--frame") {
      const std::string v = value();
      o.frame_n = std::stoi(v.substr(0, v.find(':')));
      o.frame_path = v.substr(v.find(':') + 1);
    } else if (arg == "--camera-only") {
      o.camera_only = true;
    } else if (arg == "--track") {
      o.track = true;
    } else if (arg == "--world") {
      o.world = value();
    } else {
      throw std::runtime_error("unknown argument " + arg);
    }
  }
  return o;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  try {
    o = parse(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "actors_bench: %s\n", e.what());
    return 2;
  }
  std::printf("CPU: %s, load average %s\n", first_line("/proc/cpuinfo", "model name").c_str(),
              loadavg().c_str());
  if (o.track) {
    for (int n : o.counts) track(o, n);
    return 0;
  }
  std::printf("step: wall ms (CPU ms of the process's threads)\n");
  std::printf("%6s %18s %18s %12s %10s\n", "actors", "step, no camera", "step, camera", "camera",
              "boxes per");
  std::printf("%6s %18s %18s %12s %10s\n", "", "", "", "frames/s", "frame");
  double base_plain = 0, base_camera = 0, cpu_plain = 0, cpu_camera = 0;
  std::vector<std::pair<int, Result>> plain, seen;
  for (int n : o.counts) {
    const Result p = o.camera_only ? Result{} : run(o, n, false, false);
    const Result c = run(o, n, true, n == o.frame_n);
    if (n == 0) {
      base_plain = p.step_ms, base_camera = c.step_ms;
      cpu_plain = p.cpu_ms, cpu_camera = c.cpu_ms;
    }
    std::printf("%6d %8.2f (%6.2f) %8.2f (%6.2f) %12.1f %10.1f\n", n, p.step_ms, p.cpu_ms,
                c.step_ms, c.cpu_ms, c.frames_per_s, c.boxes);
    std::fflush(stdout);
    plain.emplace_back(n, p);
    seen.emplace_back(n, c);
  }
  for (size_t i = 0; i < plain.size(); ++i) {
    const int n = plain[i].first;
    if (n == 0) continue;
    std::printf(
        "per actor at %d: %.1f us a step without the camera (CPU %.1f), %.1f us with it (CPU "
        "%.1f)\n",
        n, 1e3 * (plain[i].second.step_ms - base_plain) / n,
        1e3 * (plain[i].second.cpu_ms - cpu_plain) / n,
        1e3 * (seen[i].second.step_ms - base_camera) / n,
        1e3 * (seen[i].second.cpu_ms - cpu_camera) / n);
  }
  std::printf("load average after: %s\n", loadavg().c_str());
}
