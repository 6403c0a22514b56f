#include "model_inserts.h"

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

namespace convoy::world {
namespace {

Eigen::Isometry3d pose_from_json(const nlohmann::json& j, const std::string& where) {
  std::vector<double> v;
  if (j.is_array()) {
    for (const auto& x : j)
      if (x.is_number()) v.push_back(x.get<double>());
  } else if (j.is_string()) {
    std::istringstream in(j.get<std::string>());
    double x;
    while (in >> x) v.push_back(x);
  }
  if ((v.size() != 6 && v.size() != 3) || (j.is_array() && v.size() != j.size())) {
    throw std::runtime_error(where + ": must be [x, y, z] or [x, y, z, roll, pitch, yaw], got " +
                             j.dump());
  }
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.translation() = Eigen::Vector3d(v[0], v[1], v[2]);
  if (v.size() == 6) {
    t.linear() = (Eigen::AngleAxisd(v[5], Eigen::Vector3d::UnitZ()) *
                  Eigen::AngleAxisd(v[4], Eigen::Vector3d::UnitY()) *
                  Eigen::AngleAxisd(v[3], Eigen::Vector3d::UnitX()))
                     .toRotationMatrix();
  }
  return t;
}

double speed_from_json(const nlohmann::json& j, const std::string& where) {
  if (!j.is_number() || !(j.get<double>() >= 0) || !std::isfinite(j.get<double>()))
    throw std::runtime_error(where + ": must be a number >= 0 (m/s), got " + j.dump());
  return j.get<double>();
}

}  // namespace

std::vector<ModelInsert> read_model_inserts(const nlohmann::json& config) {
  std::vector<ModelInsert> out;
  if (!config.contains("GazeboSDFModels")) return out;
  const nlohmann::json& models = config["GazeboSDFModels"];
  if (!models.is_array()) throw std::runtime_error("GazeboSDFModels: must be an array");
  for (size_t i = 0; i < models.size(); ++i) {
    const nlohmann::json& m = models[i];
    const std::string where = "GazeboSDFModels/" + std::to_string(i);
    if (!m.is_object()) throw std::runtime_error(where + ": must be an object");
    ModelInsert insert;
    insert.name = m.value("Name", "");
    insert.file = m.value("File", "");
    if (m.contains("InitPose")) insert.pose = pose_from_json(m["InitPose"], where + "/InitPose");
    if (m.contains("InitSpeed"))
      insert.init_speed = speed_from_json(m["InitSpeed"], where + "/InitSpeed");
    out.push_back(insert);
  }
  return out;
}

std::vector<const ModelDesc*> models_of(const WorldDesc& desc, const ModelInsert& insert) {
  std::string name = insert.name;
  if (name.empty()) {
    const auto file = std::filesystem::absolute(insert.file);
    for (auto it = desc.models.rbegin(); it != desc.models.rend() && name.empty(); ++it)
      if (it->source == file && it->name.find("::") == std::string::npos) name = it->name;
    if (name.empty()) return {};
  }
  std::vector<const ModelDesc*> out;
  for (const auto& m : desc.models)
    if (m.name == name || m.name.rfind(name + "::", 0) == 0) out.push_back(&m);
  return out;
}

}  // namespace convoy::world
