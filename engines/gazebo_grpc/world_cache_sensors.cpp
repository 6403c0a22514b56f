#include "world_cache_sensors.h"

namespace convoy::world::cache_io {

namespace {

void put(Writer& w, const nav_sensors::NoiseParams& n) {
  w.pod<int32_t>(static_cast<int32_t>(n.type));
  for (double v : {n.mean, n.stddev, n.bias_mean, n.bias_stddev, n.dynamic_bias_stddev,
                   n.dynamic_bias_correlation_time, n.precision})
    w.pod(v);
}
void get(Reader& r, nav_sensors::NoiseParams& n) {
  const auto type = r.pod<int32_t>();
  if (type < 0 || type > 2) throw std::runtime_error("bad noise type");
  n.type = static_cast<nav_sensors::NoiseParams::Type>(type);
  for (double* v : {&n.mean, &n.stddev, &n.bias_mean, &n.bias_stddev, &n.dynamic_bias_stddev,
                    &n.dynamic_bias_correlation_time, &n.precision})
    *v = r.pod<double>();
}

void put(Writer& w, const NavSensorDesc& d) {
  w.pod<uint8_t>(d.kind);
  for (const auto* s : {&d.name, &d.model, &d.link, &d.plugin_name, &d.scoped_name}) w.str(*s);
  w.iso(d.pose);
  for (const auto& n : d.imu.angular_velocity) put(w, n);
  for (const auto& n : d.imu.linear_acceleration) put(w, n);
  w.pod<uint8_t>(d.imu.orientation);
  w.pod(d.imu.update_rate);
  for (const auto* n : {&d.navsat.position_horizontal, &d.navsat.position_vertical,
                        &d.navsat.velocity_horizontal, &d.navsat.velocity_vertical})
    put(w, *n);
  w.pod(d.navsat.update_rate);
}
void get(Reader& r, NavSensorDesc& d) {
  const auto kind = r.pod<uint8_t>();
  if (kind > NavSensorDesc::kNavSat) throw std::runtime_error("bad sensor kind");
  d.kind = static_cast<NavSensorDesc::Kind>(kind);
  for (auto* s : {&d.name, &d.model, &d.link, &d.plugin_name, &d.scoped_name}) *s = r.str();
  d.pose = r.iso();
  for (auto& n : d.imu.angular_velocity) get(r, n);
  for (auto& n : d.imu.linear_acceleration) get(r, n);
  d.imu.orientation = r.pod<uint8_t>() != 0;
  d.imu.update_rate = r.pod<double>();
  for (auto* n : {&d.navsat.position_horizontal, &d.navsat.position_vertical,
                  &d.navsat.velocity_horizontal, &d.navsat.velocity_vertical})
    get(r, *n);
  d.navsat.update_rate = r.pod<double>();
}

void put(Writer& w, const RadarDesc& d) {
  for (const auto* s : {&d.name, &d.model, &d.link, &d.plugin_name, &d.scoped_name}) w.str(*s);
  w.iso(d.pose);
  const radar::RadarParams& p = d.radar;
  for (double v : {p.horizontal_fov, p.vertical_fov, p.min_range, p.max_range, p.range_stddev,
                   p.azimuth_stddev, p.elevation_stddev, p.range_rate_stddev, p.rcs_stddev,
                   p.detection_range, p.clutter, p.update_rate})
    w.pod(v);
}
void get(Reader& r, RadarDesc& d) {
  for (auto* s : {&d.name, &d.model, &d.link, &d.plugin_name, &d.scoped_name}) *s = r.str();
  d.pose = r.iso();
  radar::RadarParams& p = d.radar;
  for (double* v : {&p.horizontal_fov, &p.vertical_fov, &p.min_range, &p.max_range, &p.range_stddev,
                    &p.azimuth_stddev, &p.elevation_stddev, &p.range_rate_stddev, &p.rcs_stddev,
                    &p.detection_range, &p.clutter, &p.update_rate})
    *v = r.pod<double>();
}

void put(Writer& w, const OdometryDesc& d) {
  for (const auto* s : {&d.name, &d.model, &d.link, &d.plugin_name, &d.scoped_name, &d.left_joint,
                        &d.right_joint, &d.steering_joint})
    w.str(*s);
  const auto& o = d.odometry;
  for (double v :
       {o.wheel_radius, o.track, o.wheelbase, o.scale_stddev, o.slip_stddev, o.update_rate})
    w.pod(v);
}
void get(Reader& r, OdometryDesc& d) {
  for (auto* s : {&d.name, &d.model, &d.link, &d.plugin_name, &d.scoped_name, &d.left_joint,
                  &d.right_joint, &d.steering_joint})
    *s = r.str();
  auto& o = d.odometry;
  for (double* v :
       {&o.wheel_radius, &o.track, &o.wheelbase, &o.scale_stddev, &o.slip_stddev, &o.update_rate})
    *v = r.pod<double>();
}

}  // namespace

void put_sensors(Writer& w, const LinkDesc& l) {
  w.size(l.lidars.size());
  for (const auto& d : l.lidars) {
    for (const auto* s : {&d.name, &d.model, &d.link, &d.plugin_name, &d.scoped_name}) w.str(*s);
    w.iso(d.pose);
    const lidar::LidarModel& m = d.lidar;
    for (const auto* a : {&m.horizontal, &m.vertical}) {
      w.pod<int32_t>(a->samples);
      for (double v : {a->resolution, a->min_angle, a->max_angle}) w.pod(v);
    }
    for (double v : {m.range_min, m.range_max, m.range_resolution, m.noise_mean, m.noise_stddev,
                     m.update_rate})
      w.pod(v);
    w.pod<uint8_t>(m.gaussian_noise);
  }
  w.size(l.nav_sensors.size());
  for (const auto& d : l.nav_sensors) put(w, d);
  w.size(l.radars.size());
  for (const auto& d : l.radars) put(w, d);
  w.size(l.odometers.size());
  for (const auto& d : l.odometers) put(w, d);
}

void get_sensors(Reader& r, LinkDesc& l) {
  l.lidars.resize(r.size());
  for (auto& d : l.lidars) {
    for (auto* s : {&d.name, &d.model, &d.link, &d.plugin_name, &d.scoped_name}) *s = r.str();
    d.pose = r.iso();
    lidar::LidarModel& m = d.lidar;
    for (auto* a : {&m.horizontal, &m.vertical}) {
      a->samples = r.pod<int32_t>();
      for (double* v : {&a->resolution, &a->min_angle, &a->max_angle}) *v = r.pod<double>();
    }
    for (double* v : {&m.range_min, &m.range_max, &m.range_resolution, &m.noise_mean,
                      &m.noise_stddev, &m.update_rate})
      *v = r.pod<double>();
    m.gaussian_noise = r.pod<uint8_t>() != 0;
  }
  l.nav_sensors.resize(r.size());
  for (auto& d : l.nav_sensors) get(r, d);
  l.radars.resize(r.size());
  for (auto& d : l.radars) get(r, d);
  l.odometers.resize(r.size());
  for (auto& d : l.odometers) get(r, d);
}

}  // namespace convoy::world::cache_io
