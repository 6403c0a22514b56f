#include "radar_desc.h"

#include <sdf/Element.hh>
#include <stdexcept>

#include "sdf_eigen.h"
#include "sensor_sdf.h"

namespace convoy::world {

namespace {

std::string plugin_file(const sdf::Sensor* sensor) {
  const sdf::ElementPtr e = sensor ? sensor->Element() : nullptr;
  if (!e || !e->HasElement("plugin")) return "";
  const sdf::ElementPtr p = e->GetElement("plugin");
  return p->HasAttribute("filename") ? p->GetAttribute("filename")->GetAsString() : "";
}

std::string text(const sdf::ElementPtr& plugin, const char* name, const std::string& fallback) {
  if (!plugin->HasElement(name)) return fallback;
  const auto v = plugin->GetElement(name)->GetValue();
  return v ? v->GetAsString() : fallback;
}

double number(const sdf::ElementPtr& plugin, const char* name, double fallback) {
  const std::string s = text(plugin, name, "");
  if (s.empty()) return fallback;
  try {
    size_t used = 0;
    const double v = std::stod(s, &used);
    if (s.find_first_not_of(" \t\r\n", used) == std::string::npos) return v;
  } catch (const std::exception&) {
  }
  throw std::invalid_argument(std::string("<") + name + ">: must be a number, got '" + s + "'");
}

template <typename Desc>
void names(Desc& d, const sdf::Sensor* sensor, const std::string& model, const std::string& link) {
  d.name = sensor->Name();
  d.model = model;
  d.link = link;
  d.scoped_name = model + "::" + link + "::" + sensor->Name();
  d.plugin_name = sensor_plugin_name(sensor);
}

double rate(const sdf::Sensor* sensor, const std::string& where) {
  const double r = sensor->UpdateRate();
  if (!(r >= 0)) throw std::runtime_error(where + "<update_rate>: must not be negative");
  return r;
}

}  // namespace

bool is_radar_sensor(const sdf::Sensor* sensor) {
  return sensor && sensor_type(sensor) == "custom" && radar::is_radar_plugin(plugin_file(sensor));
}

bool is_odometry_sensor(const sdf::Sensor* sensor) {
  const std::string f = plugin_file(sensor);
  return sensor && sensor_type(sensor) == "custom" &&
         (f == "convoy_wheel_odometry" || f == "libconvoy_wheel_odometry.so");
}

RadarDesc radar_desc(const sdf::Sensor* sensor, const std::string& model, const std::string& link,
                     const std::filesystem::path& file) {
  RadarDesc d;
  names(d, sensor, model, link);
  const std::string where = sensor_where(file, model, link, d.name);
  try {
    d.radar = radar::parse_radar(sensor->Element()->GetElement("plugin"));
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(where + e.what());
  }
  d.radar.update_rate = rate(sensor, where);
  ignition::math::Pose3d pose;
  if (!sensor->SemanticPose().Resolve(pose).empty())
    throw std::runtime_error(where + "its pose cannot be resolved");
  d.pose = to_eigen(pose);
  return d;
}

OdometryDesc odometry_desc(const sdf::Sensor* sensor, const std::string& model,
                           const std::string& link, const std::filesystem::path& file) {
  OdometryDesc d;
  names(d, sensor, model, link);
  const std::string where = sensor_where(file, model, link, d.name);
  const sdf::ElementPtr p = sensor->Element()->GetElement("plugin");
  try {
    d.left_joint = text(p, "left_joint", "rear_left_wheel_joint");
    d.right_joint = text(p, "right_joint", "rear_right_wheel_joint");
    d.steering_joint = text(p, "steering_joint", "");
    auto& o = d.odometry;
    o.wheel_radius = number(p, "wheel_radius", 0.3);
    o.track = number(p, "track", 1.6);
    o.wheelbase = number(p, "wheelbase", 0);
    o.scale_stddev = number(p, "scale_stddev", 0);
    o.slip_stddev = number(p, "slip_stddev", 0);
    o.validate();
  } catch (const std::invalid_argument& e) {
    std::string what = e.what();  // "field: problem" -> "<field>: problem"
    if (what[0] != '<') {
      const size_t colon = what.find(':');
      what = "<" + what.substr(0, colon) + ">" + what.substr(colon);
    }
    throw std::runtime_error(where + what);
  }
  d.odometry.update_rate = rate(sensor, where);
  return d;
}

}  // namespace convoy::world
