#include "systems/lidar_sensors.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "camera_sensors.h"
#include "convoy/point_cloud.pb.h"
#include "datapack/proto.h"
#include "datapack/registry.h"
#include "physics_world.h"

namespace convoy::world {

namespace {

render::Pose to_pose(const Eigen::Isometry3d& t) {
  render::Pose p{};
  const Eigen::Matrix4d m = t.matrix();
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) p[c * 4 + r] = m(r, c);
  return p;
}

lidar::LidarWeather lidar_weather(const Weather* w) {
  lidar::LidarWeather out;
  if (!w) return out;
  if (std::isfinite(w->visibility_m) && w->visibility_m < 1e6)
    out.visibility = static_cast<float>(w->visibility_m);
  out.precipitation = static_cast<float>(std::clamp(w->precipitation, 0.0, 1.0));
  out.snow = w->snow;
  return out;
}

std::string sensor_where(const LidarDesc& d) {
  return "model '" + d.model + "' link '" + d.link + "' sensor '" + d.name + "': ";
}

}  // namespace

LidarSensors::LidarSensors() = default;
LidarSensors::~LidarSensors() = default;

void LidarSensors::configure(const WorldContext& ctx, const nlohmann::json& config) {
  ctx_ = &ctx;
  const double step_s = config.value("EngineTimestep", 0.01);
  const uint64_t seed = config.value("GazeboRNGSeed", uint64_t{0});
  uint32_t model_id = 0;
  for (size_t m = 0; m < ctx.desc->models.size(); ++m) {
    const ModelDesc& model = ctx.desc->models[m];
    ++model_id;
    for (const auto& link : model.links)
      for (const auto& d : link.lidars) {
        if (step_s > 0 && d.lidar.update_rate > 1.0 / step_s * (1 + 1e-9)) {
          std::ostringstream s;
          s << "engine '" << ctx.engine << "': " << sensor_where(d)
            << "<update_rate>: " << d.lidar.update_rate
            << " Hz is above the engine's step rate (1 / EngineTimestep = " << 1.0 / step_s
            << " Hz)";
          throw std::runtime_error(s.str());
        }
        Sensor s;
        s.desc = &d;
        s.link = ctx.physics->link_index(link.name);
        s.link_pose = link.pose;
        s.own_model = model_id;
        s.seed = seed + sensors_.size();
        try {
          s.sensor = std::make_unique<lidar::LidarSensor>(d.lidar);
        } catch (const std::invalid_argument& e) {
          throw std::runtime_error(sensor_where(d) + e.what());
        }
        std::vector<std::string> names{d.scoped_name};
        if (!d.plugin_name.empty()) names.push_back(d.plugin_name + "::" + d.name);
        for (const auto& n : names) {
          book_.add_name(n, sensors_.size());
          provided_.push_back({n, datapack::type_name<data::PointCloud>(), static_cast<int>(m)});
        }
        sensors_.push_back(std::move(s));
      }
  }
}

void LidarSensors::scan(Sensor& s) {
  CameraSensors& cameras = *ctx_->cameras;
  if (!scene_) scene_ = std::make_unique<lidar::LidarScene>(cameras.scene());
  cameras.refresh_poses();
  scene_->update(cameras.scene());
  // A link the physics does not simulate (a static model's without collisions) stays put.
  const Eigen::Isometry3d link = s.link >= 0 ? ctx_->physics->link_pose(s.link) : s.link_pose;
  const Eigen::Isometry3d pose = link * s.desc->pose;
  s.sensor->scan(*scene_, to_pose(pose), ctx_->time_s(), s.seed, lidar_weather(cameras.weather()),
                 &s.cloud);
  auto& pts = s.cloud.points;
  pts.erase(std::remove_if(pts.begin(), pts.end(),
                           [&](const lidar::Point& p) { return p.instance == s.own_model; }),
            pts.end());
  const double rate = s.desc->lidar.update_rate;
  ScanBook<Sensor>::scanned(s, ctx_->time_s(), rate > 0 ? 1.0 / rate : 0);
}

void LidarSensors::fill(const Sensor& s, datapack::Builder& out) const {
  static const struct {
    const char* name;
    uint32_t offset;
    const char* dtype;
  } kFields[] = {{"x", 0, "<f4"},          {"y", 4, "<f4"},         {"z", 8, "<f4"},
                 {"intensity", 12, "<f4"}, {"instance", 16, "<u4"}, {"label", 20, "<u4"},
                 {"ring", 24, "<u2"},      {"column", 26, "<u2"},   {"flags", 28, "<u4"}};
  data::PointCloud m;
  m.set_time_ns(std::llround(s.cloud.time * 1e9));
  m.set_point_step(sizeof(lidar::Point));
  for (const auto& f : kFields) {
    auto* pf = m.add_fields();
    pf->set_name(f.name);
    pf->set_offset(f.offset);
    pf->set_dtype(f.dtype);
  }
  const auto& pts = s.cloud.points;
  m.set_points(reinterpret_cast<const char*>(pts.data()), pts.size() * sizeof(lidar::Point));
  m.set_rings(static_cast<uint32_t>(s.desc->lidar.vertical.samples));
  m.set_columns(static_cast<uint32_t>(s.desc->lidar.horizontal.samples));
  m.set_count(static_cast<uint32_t>(pts.size()));
  m.set_frame(s.desc->scoped_name);
  auto& instances = *m.mutable_instances();
  const CameraSensors& cameras = *ctx_->cameras;
  for (const auto& p : pts) {
    if (p.instance == 0 || instances.contains(p.instance)) continue;
    data::PointCloudInstance& gt = instances[p.instance];
    gt.set_model(cameras.model_name(p.instance));
    gt.set_class_name(cameras.model_class(p.instance));
  }
  datapack::write_proto(out, m);
}

void LidarSensors::get_datapack(const std::string& name, datapack::Builder& out) {
  Sensor* s = book_.want(name, [this](Sensor& x) { scan(x); });
  if (!s) return;
  fill(*s, out);
  book_.sent(name);
}

bool LidarSensors::unchanged(const std::string& name) { return book_.unchanged(name); }

void LidarSensors::after_step() {
  book_.scan_due(ctx_->time_s(), 0.5 * ctx_->physics->step_size(), [this](Sensor& s) { scan(s); });
}

void LidarSensors::reset() {
  scene_.reset();  // the cameras' scene was made again
  book_.reset();
  for (auto& s : sensors_) s.cloud = {};
}

}  // namespace convoy::world
