#include "lidar_desc.h"

#include <sdf/Element.hh>
#include <stdexcept>

#include "sdf_eigen.h"
#include "sensor_sdf.h"

namespace convoy::world {

bool is_lidar_sensor(const sdf::Sensor* sensor) {
  return sensor && lidar::is_lidar_type(sensor_type(sensor));
}

LidarDesc lidar_desc(const sdf::Sensor* sensor, const std::string& model, const std::string& link,
                     const std::filesystem::path& file) {
  LidarDesc d;
  d.name = sensor->Name();
  d.model = model;
  d.link = link;
  d.scoped_name = model + "::" + link + "::" + sensor->Name();
  const std::string where = sensor_where(file, model, link, d.name);
  try {
    d.lidar = lidar::parse_lidar(sensor->Element());
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(where + e.what());
  }
  ignition::math::Pose3d pose;
  if (!sensor->SemanticPose().Resolve(pose).empty())
    throw std::runtime_error(where + "its pose cannot be resolved");
  d.pose = to_eigen(pose);
  d.plugin_name = sensor_plugin_name(sensor);
  return d;
}

}  // namespace convoy::world
