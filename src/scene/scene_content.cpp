#include "scene/scene_content.h"

#include <string_view>

#include "datapack/json.h"
#include "datapack/proto.h"

namespace convoy::scene {

namespace {

using google::protobuf::FieldDescriptor;
using nlohmann::json;

void set_field(const json& v, const FieldDescriptor* f, data::RoadUser* u) {
  const auto* r = u->GetReflection();
  switch (f->cpp_type()) {
    case FieldDescriptor::CPPTYPE_DOUBLE:
      if (v.is_number()) r->SetDouble(u, f, v.get<double>());
      break;
    case FieldDescriptor::CPPTYPE_STRING:
      if (v.is_string()) r->SetString(u, f, v.get<std::string>());
      break;
    case FieldDescriptor::CPPTYPE_BOOL:
      if (v.is_boolean()) r->SetBool(u, f, v.get<bool>());
      break;
    case FieldDescriptor::CPPTYPE_INT32:
      if (v.is_number_integer()) r->SetInt32(u, f, v.get<int32_t>());
      break;
    case FieldDescriptor::CPPTYPE_INT64:
      if (v.is_number_integer()) r->SetInt64(u, f, v.get<int64_t>());
      break;
    case FieldDescriptor::CPPTYPE_UINT32:
      if (v.is_number_unsigned()) r->SetUInt32(u, f, v.get<uint32_t>());
      break;
    default:
      break;
  }
}

std::vector<Point3> route_of(const json& value) {
  std::vector<Point3> out;
  if (!value.is_array()) return out;
  for (const json& p : value) {
    if (p.is_array() && p.size() >= 2 && p[0].is_number() && p[1].is_number()) {
      out.push_back({p[0].get<double>(), p[1].get<double>(),
                     p.size() > 2 && p[2].is_number() ? p[2].get<double>() : 0.0});
    } else if (p.is_object() && p.contains("x") && p.contains("y") && p["x"].is_number() &&
               p["y"].is_number()) {
      out.push_back({p["x"].get<double>(), p["y"].get<double>(), p.value("z", 0.0)});
    }
  }
  return out;
}

void users_of(const json& list, SceneContent& out) {
  out.user_set = true;
  for (const json& item : list) {
    data::RoadUser u;
    if (road_user_from_json(item, &u)) out.users.push_back(std::move(u));
  }
}

void read_json_content(const json& j, SceneContent& out) {
  if (j.is_array()) {
    if (!j.empty() && j.front().is_object()) users_of(j, out);
    return;
  }
  if (!j.is_object()) return;
  data::RoadUser u;
  if (road_user_from_json(j, &u)) {
    out.users.push_back(std::move(u));
  } else if (auto it = j.find("users"); it != j.end() && it->is_array()) {
    users_of(*it, out);
  }
  if (auto it = j.find("signals"); it != j.end() && it->is_object()) {
    out.has_signals = true;
    for (const auto& [id, state] : it->items())
      if (state.is_string()) out.signals[id] = state.get<std::string>();
  }
  if (auto it = j.find("route"); it != j.end()) out.route = route_of(*it);
}

// Whether MessagePack bytes may hold one of the keys the scene reads: a key of up to 31 bytes
// is a fixstr (0xa0 | length, then the bytes) in every encoder Convoy uses, so a datapack
// without these byte strings is not parsed at all.
bool may_hold_scene_keys(std::string_view msgpack) {
  using namespace std::string_view_literals;
  for (std::string_view key : {"\xa2id"sv, "\xa7signals"sv, "\xa5route"sv, "\xa5users"sv})
    if (msgpack.find(key) != std::string_view::npos) return true;
  return false;
}

}  // namespace

bool road_user_from_json(const json& j, data::RoadUser* out) {
  if (!j.is_object()) return false;
  const auto id = j.find("id"), x = j.find("x"), y = j.find("y");
  if (id == j.end() || !id->is_string() || x == j.end() || !x->is_number() || y == j.end() ||
      !y->is_number())
    return false;
  const auto* desc = data::RoadUser::descriptor();
  for (const auto& [key, value] : j.items()) {
    if (const FieldDescriptor* f = desc->FindFieldByName(key)) set_field(value, f, out);
  }
  return true;
}

SceneContent read_scene_content(const datapack::View& dp) {
  SceneContent out;
  try {
    if (dp.is_proto()) {
      const std::string& type = dp.proto_type();
      if (type == data::RoadUser::descriptor()->full_name()) {
        out.users.push_back(datapack::read_proto<data::RoadUser>(dp));
      } else if (type == data::RoadUsers::descriptor()->full_name()) {
        auto users = datapack::read_proto<data::RoadUsers>(dp);
        out.user_set = true;
        for (auto& u : *users.mutable_users()) out.users.push_back(std::move(u));
      }
    } else if (dp.is_json() && dp.message().json_msgpack().size() <= kMaxSceneJsonBytes &&
               may_hold_scene_keys(dp.message().json_msgpack())) {
      read_json_content(datapack::read_json(dp), out);
    }
  } catch (const std::exception&) {
    return {};  // malformed: the scene leaves it out, the datapack's own channel shows it
  }
  return out;
}

}  // namespace convoy::scene
