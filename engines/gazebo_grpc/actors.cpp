#include "actors.h"

#include <google/protobuf/descriptor.h>
#include <google/protobuf/reflection.h>

#include <fstream>
#include <stdexcept>

namespace convoy::world {

namespace fs = std::filesystem;

namespace {

fs::path default_table() {
  std::error_code ec;
  fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    fs::path p =
        exe.parent_path().parent_path() / "share" / "convoy" / "actors" / "actor_models.json";
    if (fs::exists(p)) return p;
  }
#ifdef CONVOY_ACTOR_DIR
  return fs::path(CONVOY_ACTOR_DIR) / "actor_models.json";
#else
  return {};
#endif
}

Eigen::Isometry3d scaled_pose(Eigen::Isometry3d p, const Eigen::Vector3d& s) {
  p.translation() = p.translation().cwiseProduct(s);
  return p;
}

// The scale along a shape's own axes for a model scale `s` (its pose's rotation taken into
// account for right-angle rotations, the usual case).
Eigen::Vector3d local_scale(const Eigen::Isometry3d& pose, const Eigen::Vector3d& s) {
  return (pose.linear().transpose().cwiseAbs() * s).eval();
}

Shape scaled_shape(Shape sh, const Eigen::Isometry3d& pose, const Eigen::Vector3d& s) {
  Eigen::Vector3d ls = local_scale(pose, s);
  switch (sh.kind) {
    case Shape::kBox:
      sh.size = sh.size.cwiseProduct(ls);
      break;
    case Shape::kCylinder: {
      double r = sh.size.x() * std::sqrt(ls.x() * ls.y());
      sh.size = {r, r, sh.size.z() * ls.z()};
      break;
    }
    case Shape::kSphere:
      sh.size *= std::cbrt(ls.x() * ls.y() * ls.z());
      break;
    case Shape::kMesh:
      sh.scale = sh.scale.cwiseProduct(ls);
      break;
    case Shape::kPlane:
    case Shape::kHeightmap:
      break;
  }
  return sh;
}

}  // namespace

ActorLibrary::ActorLibrary(const fs::path& table)
    : table_(table.empty() ? default_table() : table) {
  std::ifstream in(table_);
  if (!in) throw std::runtime_error(table_.string() + ": actor model table not found");
  try {
    json_ = nlohmann::json::parse(in);
  } catch (const std::exception& e) {
    throw std::runtime_error(table_.string() + ": not JSON: " + e.what());
  }
  if (!json_.contains("models") || !json_["models"].is_object())
    throw std::runtime_error(table_.string() + ": no \"models\" object");
}

const ActorModel& ActorLibrary::find(const std::string& model, const std::string& category) {
  std::string key = model;
  const auto& models = json_["models"];
  if (key.empty() || !models.contains(key)) {
    const auto cats = json_.value("categories", nlohmann::json::object());
    if (!cats.contains(category)) {
      throw std::runtime_error("no actor model for model '" + model + "', category '" + category +
                               "' (models and categories: " + table_.string() + ")");
    }
    key = cats[category].get<std::string>();
  }
  if (auto it = loaded_.find(key); it != loaded_.end()) return it->second;
  if (!models.contains(key))
    throw std::runtime_error(table_.string() + ": category '" + category + "' names model '" + key +
                             "', which is not in \"models\"");
  const auto& e = models[key];
  ActorModel am;
  am.key = key;
  try {
    am.file = table_.parent_path() / e.at("file").get<std::string>();
    am.cls = e.at("class").get<std::string>();
    auto size = e.at("size").get<std::vector<double>>();
    if (size.size() != 3) throw std::runtime_error("size must be [length, width, height]");
    am.size = {size[0], size[1], size[2]};
    am.length_offset = e.value("length_offset", 0.0);
  } catch (const std::exception& ex) {
    throw std::runtime_error(table_.string() + ": model '" + key + "': " + ex.what());
  }
  if (!is_known_class(am.cls))
    throw std::runtime_error(table_.string() + ": model '" + key + "': unknown class '" + am.cls +
                             "'");
  auto descs = load_model(am.file, key, Eigen::Isometry3d::Identity());
  am.desc = std::move(descs.front());
  try {
    if (e.contains("walk_cycle")) {
      for (const auto& f : e.at("walk_cycle")) {
        const std::string file = f.get<std::string>();
        auto pose = load_model(table_.parent_path() / file, key, Eigen::Isometry3d::Identity());
        am.walk_cycle.push_back(std::move(pose.front()));
      }
    }
    if (e.contains("stand")) {
      const std::string stand = e.at("stand").get<std::string>();
      if (!models.contains(stand))
        throw std::runtime_error("\"stand\": '" + stand + "' is not in \"models\"");
      auto pose = load_model(table_.parent_path() / models[stand].at("file").get<std::string>(),
                             key, Eigen::Isometry3d::Identity());
      am.stand.push_back(std::move(pose.front()));
    }
  } catch (const std::exception& ex) {
    throw std::runtime_error(table_.string() + ": model '" + key + "': " + ex.what());
  }
  return loaded_.emplace(key, std::move(am)).first->second;
}

ModelDesc scaled(const ModelDesc& m, const Eigen::Vector3d& s) {
  ModelDesc out = m;
  for (auto& l : out.links) {
    Eigen::Isometry3d lp = l.pose;
    l.pose = scaled_pose(l.pose, s);
    Eigen::Vector3d ls = local_scale(lp, s);
    for (auto& c : l.collisions) {
      c.shape = scaled_shape(c.shape, lp * c.pose, s);
      c.pose = scaled_pose(c.pose, ls);
    }
    for (auto& v : l.visuals) {
      v.shape = scaled_shape(v.shape, lp * v.pose, s);
      v.pose = scaled_pose(v.pose, ls);
    }
  }
  return out;
}

std::vector<data::RoadUser> road_users_from_json(const nlohmann::json& j) {
  std::vector<data::RoadUser> out;
  if (j.is_array()) {
    for (const auto& u : j) {
      auto v = road_users_from_json(u);
      out.insert(out.end(), v.begin(), v.end());
    }
    return out;
  }
  if (!j.is_object()) throw std::runtime_error("a road user must be a JSON object");
  if (j.contains("users")) return road_users_from_json(j["users"]);
  data::RoadUser u;
  const auto* desc = u.GetDescriptor();
  const auto* refl = u.GetReflection();
  namespace pb = google::protobuf;
  for (const auto& [key, value] : j.items()) {
    const pb::FieldDescriptor* f = desc->FindFieldByName(key);
    if (!f) throw std::runtime_error("road user: unknown key '" + key + "'");
    try {
      switch (f->cpp_type()) {
        case pb::FieldDescriptor::CPPTYPE_STRING:
          refl->SetString(&u, f, value.get<std::string>());
          break;
        case pb::FieldDescriptor::CPPTYPE_BOOL:
          refl->SetBool(&u, f, value.get<bool>());
          break;
        case pb::FieldDescriptor::CPPTYPE_DOUBLE:
          if (!value.is_number()) throw std::runtime_error("not a number");
          refl->SetDouble(&u, f, value.get<double>());
          break;
        case pb::FieldDescriptor::CPPTYPE_UINT32:
          refl->SetUInt32(&u, f, value.get<uint32_t>());
          break;
        case pb::FieldDescriptor::CPPTYPE_INT32:
          refl->SetInt32(&u, f, value.get<int32_t>());
          break;
        case pb::FieldDescriptor::CPPTYPE_INT64:
          refl->SetInt64(&u, f, value.get<int64_t>());
          break;
        default:
          throw std::runtime_error("unsupported field type");
      }
    } catch (const std::exception& e) {
      throw std::runtime_error("road user: key '" + key + "': " + e.what());
    }
  }
  out.push_back(std::move(u));
  return out;
}

Eigen::Isometry3d road_user_pose(const data::RoadUser& u) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.translation() = Eigen::Vector3d(u.x(), u.y(), u.z());
  t.linear() = (Eigen::AngleAxisd(u.yaw(), Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(u.pitch(), Eigen::Vector3d::UnitY()) *
                Eigen::AngleAxisd(u.roll(), Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  return t;
}

}  // namespace convoy::world
