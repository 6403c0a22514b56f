#include "sensor_config.h"

#include <sdf/Link.hh>
#include <sdf/Model.hh>
#include <sdf/Root.hh>
#include <sstream>
#include <stdexcept>

#include "lidar_desc.h"
#include "nav_desc.h"
#include "radar_desc.h"

namespace convoy::world {
namespace {

std::string who(const config::SensorEntry& e) {
  return "model '" + e.model + "' link '" + e.link + "' sensor '" + e.name + "': ";
}

// `entry`'s sensor through libsdformat, in a one-link model; its description as if the
// model's SDF had it.
void describe(const config::SensorEntry& e, const std::string& where, LinkDesc* link) {
  const std::string text =
      "<?xml version=\"1.0\"?><sdf version=\"1.7\"><model name=\"m\">"
      "<link name=\"l\">" +
      sensor_sdf_text(e) + "</link></model></sdf>";
  sdf::Root root;
  const sdf::Errors errors = root.LoadSdfString(text);
  const sdf::Model* model = root.Model();
  const sdf::Link* l = model ? model->LinkByIndex(0) : nullptr;
  if (!errors.empty() || !l || l->SensorCount() != 1) {
    std::string what = errors.empty() ? "not a sensor" : errors.front().Message();
    throw std::runtime_error(where + who(e) + "its SDF is refused: " + what);
  }
  const sdf::Sensor* sensor = l->SensorByIndex(0);
  const std::filesystem::path file = where.substr(0, where.size() - 2);  // "Sensors/i"
  if (is_lidar_sensor(sensor)) {
    LidarDesc d = lidar_desc(sensor, e.model, e.link, file);
    d.scoped_name = e.model + "::" + e.link + "::" + e.name;
    link->lidars.push_back(std::move(d));
  } else if (is_nav_sensor(sensor)) {
    NavSensorDesc d = nav_desc(sensor, e.model, e.link, file);
    d.scoped_name = e.model + "::" + e.link + "::" + e.name;
    link->nav_sensors.push_back(std::move(d));
  } else if (is_radar_sensor(sensor)) {
    RadarDesc d = radar_desc(sensor, e.model, e.link, file);
    d.scoped_name = e.model + "::" + e.link + "::" + e.name;
    d.plugin_name.clear();  // the config's own plugin: no second datapack name
    link->radars.push_back(std::move(d));
  } else if (is_odometry_sensor(sensor)) {
    OdometryDesc d = odometry_desc(sensor, e.model, e.link, file);
    d.scoped_name = e.model + "::" + e.link + "::" + e.name;
    d.plugin_name.clear();
    link->odometers.push_back(std::move(d));
  } else {
    throw std::runtime_error(where + who(e) + "unknown type '" + e.type + "'");
  }
}

// The odometer's joints in `model` (before the run, as a link is).
void check_joints(const config::SensorEntry& e, const std::string& where, const ModelDesc& model) {
  for (const auto& [key, joint] :
       {std::pair<const char*, const std::string*>{"LeftJoint", &e.left_joint},
        {"RightJoint", &e.right_joint},
        {"SteeringJoint", &e.steering_joint}}) {
    if (joint->empty()) continue;
    bool found = false;
    for (const auto& j : model.joints) found = found || j.short_name == *joint;
    if (found) continue;
    std::string known;
    for (const auto& j : model.joints) known += (known.empty() ? "" : ", ") + j.short_name;
    throw std::runtime_error(where + who(e) + key + ": model '" + e.model + "' has no joint '" +
                             *joint + "' (joints: " + known + ")");
  }
}

void radar_text(const config::SensorEntry& e, std::ostream& s) {
  s << "<plugin filename=\"convoy_radar\" name=\"" << e.name << "\">"
    << "<horizontal_fov>" << e.h_fov << "</horizontal_fov><vertical_fov>" << e.v_fov
    << "</vertical_fov><min_range>" << e.range_min << "</min_range><max_range>" << e.range_max
    << "</max_range><range_stddev>" << e.range_stddev << "</range_stddev><azimuth_stddev>"
    << e.azimuth_stddev << "</azimuth_stddev><elevation_stddev>" << e.elevation_stddev
    << "</elevation_stddev><range_rate_stddev>" << e.range_rate_stddev
    << "</range_rate_stddev><rcs_stddev>" << e.rcs_stddev << "</rcs_stddev><detection_range>"
    << e.detection_range << "</detection_range><clutter>" << e.clutter << "</clutter></plugin>";
}

void odometry_text(const config::SensorEntry& e, std::ostream& s) {
  s << "<plugin filename=\"convoy_wheel_odometry\" name=\"" << e.name << "\"><left_joint>"
    << e.left_joint << "</left_joint><right_joint>" << e.right_joint << "</right_joint>";
  if (!e.steering_joint.empty()) s << "<steering_joint>" << e.steering_joint << "</steering_joint>";
  s << "<wheel_radius>" << e.wheel_radius << "</wheel_radius><track>" << e.track
    << "</track><wheelbase>" << e.wheelbase << "</wheelbase><scale_stddev>" << e.scale_stddev
    << "</scale_stddev><slip_stddev>" << e.slip_stddev << "</slip_stddev></plugin>";
}

}  // namespace

std::string sensor_sdf_text(const config::SensorEntry& e) {
  std::ostringstream s;
  s.precision(17);
  const bool custom = e.type == "radar" || e.type == "wheel_odometry";
  s << "<sensor name=\"" << e.name << "\" type=\"" << (custom ? "custom" : e.type) << "\"><pose>";
  for (int i = 0; i < 6; ++i) s << (i ? " " : "") << e.pose[i];
  s << "</pose><update_rate>" << e.update_rate << "</update_rate>";
  if (e.is_lidar()) {
    const char* tag = e.type == "ray" || e.type == "gpu_ray" ? "ray" : "lidar";
    s << "<" << tag << "><scan><horizontal><samples>" << e.h_samples
      << "</samples><resolution>1</resolution><min_angle>" << e.h_min << "</min_angle><max_angle>"
      << e.h_max << "</max_angle></horizontal><vertical><samples>" << e.v_samples
      << "</samples><resolution>1</resolution><min_angle>" << e.v_min << "</min_angle><max_angle>"
      << e.v_max << "</max_angle></vertical></scan><range><min>" << e.range_min << "</min><max>"
      << e.range_max << "</max><resolution>" << e.range_resolution << "</resolution></range>";
    if (e.noise_stddev > 0)
      s << "<noise><type>gaussian</type><mean>0</mean><stddev>" << e.noise_stddev
        << "</stddev></noise>";
    s << "</" << tag << ">";
  }
  if (e.type == "radar") radar_text(e, s);
  if (e.type == "wheel_odometry") odometry_text(e, s);
  s << e.sdf << "</sensor>";
  return s.str();
}

void mount_config_sensors(const nlohmann::json& config, double step_s, WorldDesc* desc) {
  config::Problems problems;
  const auto entries = config::read_sensor_entries(config, step_s, "", &problems);
  if (!problems.empty())  // "/Sensors/i/Key"
    throw std::runtime_error(problems.front().first.substr(1) + ": " + problems.front().second);
  for (size_t i = 0; i < entries.size(); ++i) {
    const config::SensorEntry& e = entries[i];
    const std::string where = "Sensors/" + std::to_string(i) + ": ";
    ModelDesc* model = nullptr;
    for (auto& m : desc->models)
      if (m.name == e.model) model = &m;
    if (!model)
      throw std::runtime_error(where + who(e) + "no model '" + e.model + "' in the world");
    LinkDesc* link = nullptr;
    for (auto& l : model->links)
      if (l.short_name == e.link) link = &l;
    if (!link) {
      std::string known;
      for (const auto& l : model->links) known += (known.empty() ? "" : ", ") + l.short_name;
      throw std::runtime_error(where + who(e) + "model '" + e.model + "' has no link '" + e.link +
                               "' (links: " + known + ")");
    }
    if (e.type == "wheel_odometry") check_joints(e, where, *model);
    describe(e, where, link);
  }
}

}  // namespace convoy::world
