#include "systems/radar_sensors.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "camera_sensors.h"
#include "convoy/radar.pb.h"
#include "datapack/proto.h"
#include "datapack/registry.h"
#include "nav_sensors/noise.h"
#include "physics_world.h"
#include "radar/radar_view.h"

namespace convoy::world {

namespace {

std::string sensor_where(const RadarDesc& d) {
  return "model '" + d.model + "' link '" + d.link + "' sensor '" + d.name + "': ";
}

}  // namespace

RadarSensors::RadarSensors() = default;
RadarSensors::~RadarSensors() = default;

void RadarSensors::configure(const WorldContext& ctx, const nlohmann::json& config) {
  ctx_ = &ctx;
  const double step_s = config.value("EngineTimestep", 0.01);
  const uint64_t seed = config.value("GazeboRNGSeed", uint64_t{0});
  for (size_t m = 0; m < ctx.desc->models.size(); ++m)
    for (const auto& link : ctx.desc->models[m].links)
      for (const auto& d : link.radars) {
        if (step_s > 0 && d.radar.update_rate > 1.0 / step_s * (1 + 1e-9)) {
          std::ostringstream s;
          s << "engine '" << ctx.engine << "': " << sensor_where(d)
            << "<update_rate>: " << d.radar.update_rate
            << " Hz is above the engine's step rate (1 / EngineTimestep = " << 1.0 / step_s
            << " Hz)";
          throw std::runtime_error(s.str());
        }
        try {
          d.radar.validate();
        } catch (const std::invalid_argument& e) {
          throw std::runtime_error("engine '" + ctx.engine + "': " + sensor_where(d) + e.what());
        }
        Sensor s;
        s.desc = &d;
        s.link = ctx.physics->link_index(link.name);
        s.link_pose = link.pose;
        s.own_model = static_cast<uint32_t>(m + 1);
        s.seed = nav_sensors::random_bits(seed, 0x524144 /* "RAD" */, sensors_.size());
        std::vector<std::string> names{d.scoped_name};
        if (!d.plugin_name.empty()) names.push_back(d.plugin_name + "::" + d.name);
        for (const auto& n : names) {
          book_.add_name(n, sensors_.size());
          provided_.push_back({n, datapack::type_name<data::Radar>(), static_cast<int>(m)});
        }
        sensors_.push_back(std::move(s));
      }
}

void RadarSensors::track() {
  CameraSensors& cameras = *ctx_->cameras;
  cameras.refresh_poses();
  objects_.track(cameras.scene(), ctx_->time_s());
}

void RadarSensors::scan(Sensor& s) {
  CameraSensors& cameras = *ctx_->cameras;
  if (!scene_) scene_ = std::make_unique<lidar::LidarScene>(cameras.scene());
  if (!objects_.tracked()) track();  // asked before the first step: all at rest
  cameras.refresh_poses();
  scene_->update(cameras.scene());
  Eigen::Isometry3d link = s.link_pose;
  Eigen::Vector3d v_link = Eigen::Vector3d::Zero(), w = Eigen::Vector3d::Zero();
  if (s.link >= 0) {
    const LinkState st = ctx_->physics->link_state(s.link);
    link = ctx_->physics->link_pose(s.link);
    v_link = st.linear_velocity;
    w = st.angular_velocity;
  }
  const Eigen::Isometry3d pose = link * s.desc->pose;
  const Eigen::Vector3d v_sensor = v_link + w.cross(pose.translation() - link.translation());
  const auto targets = radar::visible_targets(
      s.desc->radar, *scene_, objects_.objects(cameras.scene()), pose, v_sensor, s.own_model,
      [&](uint32_t id) { return cameras.model_class(id); });
  s.time = ctx_->time_s();
  s.detections = radar::detect(s.desc->radar, targets, pose.linear().transpose() * v_sensor, s.seed,
                               ctx_->time_ns);
  const double rate = s.desc->radar.update_rate;
  ScanBook<Sensor>::scanned(s, s.time, rate > 0 ? 1.0 / rate : 0);
}

void RadarSensors::fill(const Sensor& s, datapack::Builder& out) const {
  data::Radar m;
  m.set_time_ns(std::llround(s.time * 1e9));
  m.set_frame(s.desc->scoped_name);
  const CameraSensors& cameras = *ctx_->cameras;
  for (const radar::Detection& d : s.detections) {
    data::RadarDetection* r = m.add_detections();
    r->set_range(d.range);
    r->set_azimuth(d.azimuth);
    r->set_elevation(d.elevation);
    r->set_range_rate(d.range_rate);
    r->set_rcs(d.rcs);
    r->set_snr(d.snr);
    r->set_clutter(d.clutter);
    if (d.id == 0) continue;
    r->set_instance(d.id);
    r->set_model(cameras.model_name(d.id));
    r->set_class_name(cameras.model_class(d.id));
  }
  datapack::write_proto(out, m);
}

void RadarSensors::get_datapack(const std::string& name, datapack::Builder& out) {
  Sensor* s = book_.want(name, [this](Sensor& x) { scan(x); });
  if (!s) return;
  fill(*s, out);
  book_.sent(name);
}

bool RadarSensors::unchanged(const std::string& name) { return book_.unchanged(name); }

void RadarSensors::after_step() {
  if (sensors_.empty()) return;
  track();
  book_.scan_due(ctx_->time_s(), 0.5 * ctx_->physics->step_size(), [this](Sensor& s) { scan(s); });
}

void RadarSensors::reset() {
  scene_.reset();  // the cameras' scene was made again
  objects_.reset();
  book_.reset();
  for (auto& s : sensors_) {
    s.detections.clear();
    s.time = 0;
  }
}

}  // namespace convoy::world
