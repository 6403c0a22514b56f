// What every sensor description reads the same way from libsdformat's DOM (lidar_desc,
// nav_desc): the type attribute as written, the <plugin name>, and where a message about the
// sensor starts.
#pragma once

#include <filesystem>
#include <sdf/Sensor.hh>
#include <string>

namespace convoy::world {

// The <sensor type="..."> attribute as written ("gpu_lidar", "navsat"...), "" if none.
inline std::string sensor_type(const sdf::Sensor* sensor) {
  const sdf::ElementPtr e = sensor->Element();
  return e && e->HasAttribute("type") ? e->GetAttribute("type")->GetAsString() : "";
}

// Its <plugin name="...">, "" if none.
inline std::string sensor_plugin_name(const sdf::Sensor* sensor) {
  const sdf::ElementPtr e = sensor->Element();
  if (!e || !e->HasElement("plugin")) return "";
  const sdf::ElementPtr p = e->GetElement("plugin");
  return p->HasAttribute("name") ? p->GetAttribute("name")->GetAsString() : "";
}

// "<file>: model 'M' link 'L' sensor 'S': ".
inline std::string sensor_where(const std::filesystem::path& file, const std::string& model,
                                const std::string& link, const std::string& sensor) {
  return file.string() + ": model '" + model + "' link '" + link + "' sensor '" + sensor + "': ";
}

}  // namespace convoy::world
