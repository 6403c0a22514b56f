// Datapacks and checks shared by the scene tests.
#pragma once

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>

#include "convoy/road_users.pb.h"
#include "datapack/json.h"
#include "datapack/proto.h"

namespace convoy::scene::testing {

inline engine::DataPack proto_datapack(const std::string& name,
                                       const google::protobuf::Message& m) {
  engine::DataPack dp;
  dp.mutable_id()->set_name(name);
  datapack::InlineBlobWriter writer;
  datapack::Builder b(&dp, writer);
  datapack::write_proto(b, m);
  return dp;
}

inline engine::DataPack json_datapack(const std::string& name, const nlohmann::json& value) {
  engine::DataPack dp;
  dp.mutable_id()->set_name(name);
  datapack::InlineBlobWriter writer;
  datapack::Builder b(&dp, writer);
  datapack::write_json(b, value);
  return dp;
}

inline data::RoadUser user(const std::string& id, const std::string& category, double x, double y,
                           double yaw = 0) {
  data::RoadUser u;
  u.set_id(id);
  u.set_category(category);
  u.set_x(x);
  u.set_y(y);
  u.set_yaw(yaw);
  return u;
}

// Checks `value` against a JSON Schema of record/scene_schemas.h strictly: every key of an
// object must be one of its schema's properties, types and enums must match.
inline void expect_valid(const nlohmann::json& value, const nlohmann::json& schema,
                         const std::string& where = "") {
  using nlohmann::json;
  if (schema.contains("type")) {
    const std::string type = schema["type"];
    const bool ok =
        (type == "object" && value.is_object()) || (type == "array" && value.is_array()) ||
        (type == "string" && value.is_string()) || (type == "boolean" && value.is_boolean()) ||
        (type == "integer" && value.is_number_integer()) || (type == "number" && value.is_number());
    ASSERT_TRUE(ok) << where << ": " << value.dump().substr(0, 200) << " is no " << type;
  }
  if (schema.contains("enum")) {
    bool found = false;
    for (const json& e : schema["enum"]) found = found || e == value;
    EXPECT_TRUE(found) << where << ": " << value;
  }
  if (value.is_object() && schema.contains("properties")) {
    for (const auto& [key, v] : value.items()) {
      ASSERT_TRUE(schema["properties"].contains(key)) << where << ": unknown key " << key;
      expect_valid(v, schema["properties"][key], where + "/" + key);
    }
  }
  if (value.is_array() && schema.contains("items")) {
    for (size_t i = 0; i < value.size(); ++i)
      expect_valid(value[i], schema["items"], where + "/" + std::to_string(i));
  }
}

}  // namespace convoy::scene::testing
