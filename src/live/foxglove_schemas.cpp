#include "live/foxglove_schemas.h"

#include <cmath>

#include "record/datapack_codec.h"

namespace convoy::live {

namespace {

using json = nlohmann::json;

const json kTime = {{"type", "object"},
                    {"title", "time"},
                    {"properties",
                     {{"sec", {{"type", "integer"}, {"minimum", 0}}},
                      {"nsec", {{"type", "integer"}, {"minimum", 0}, {"maximum", 999999999}}}}}};

json stamp(uint64_t ns) { return {{"sec", ns / 1000000000u}, {"nsec", ns % 1000000000u}}; }

json numbers(int n) {
  json a = {{"type", "array"}, {"items", {{"type", "number"}}}};
  if (n > 0) a["minItems"] = a["maxItems"] = n;
  return a;
}

ChannelInfo json_channel(const std::string& topic, const char* name, json properties) {
  json schema = {{"title", name}, {"type", "object"}, {"properties", std::move(properties)}};
  return {0, topic, "json", name, schema.dump(), "jsonschema"};
}

}  // namespace

ChannelInfo log_channel(const std::string& topic) {
  return json_channel(topic, "foxglove.Log",
                      {{"timestamp", kTime},
                       {"level", {{"type", "integer"}, {"enum", {0, 1, 2, 3, 4, 5}}}},
                       {"message", {{"type", "string"}}},
                       {"name", {{"type", "string"}}},
                       {"file", {{"type", "string"}}},
                       {"line", {{"type", "integer"}, {"minimum", 0}}}});
}

ChannelInfo compressed_image_channel(const std::string& topic) {
  return json_channel(topic, "foxglove.CompressedImage",
                      {{"timestamp", kTime},
                       {"frame_id", {{"type", "string"}}},
                       {"data", {{"type", "string"}, {"contentEncoding", "base64"}}},
                       {"format", {{"type", "string"}}}});
}

ChannelInfo camera_calibration_channel(const std::string& topic) {
  return json_channel(topic, "foxglove.CameraCalibration",
                      {{"timestamp", kTime},
                       {"frame_id", {{"type", "string"}}},
                       {"width", {{"type", "integer"}, {"minimum", 0}}},
                       {"height", {{"type", "integer"}, {"minimum", 0}}},
                       {"distortion_model", {{"type", "string"}}},
                       {"D", numbers(0)},
                       {"K", numbers(9)},
                       {"R", numbers(9)},
                       {"P", numbers(12)}});
}

std::string log_json(uint64_t time_ns, LogLevel level, std::string_view name,
                     std::string_view message) {
  json j = {{"timestamp", stamp(time_ns)},
            {"level", static_cast<int>(level)},
            {"message", message},
            {"name", name},
            {"file", ""},
            {"line", 0}};
  return j.dump(-1, ' ', false, json::error_handler_t::replace);
}

std::string compressed_image_json(uint64_t time_ns, std::string_view frame_id,
                                  std::string_view jpeg) {
  std::string out = R"({"timestamp":)" + stamp(time_ns).dump() + R"(,"frame_id":)" +
                    json(frame_id).dump() + R"(,"format":"jpeg","data":")";
  out += record::base64_encode(jpeg);
  out += "\"}";
  return out;
}

std::string camera_calibration_json(uint64_t time_ns, std::string_view frame_id, uint32_t width,
                                    uint32_t height, double hfov) {
  const double fx = width / (2.0 * std::tan(hfov / 2)), fy = fx;
  const double cx = width / 2.0, cy = height / 2.0;
  json j = {{"timestamp", stamp(time_ns)},
            {"frame_id", frame_id},
            {"width", width},
            {"height", height},
            {"distortion_model", "plumb_bob"},
            {"D", json::array({0, 0, 0, 0, 0})},
            {"K", {fx, 0, cx, 0, fy, cy, 0, 0, 1}},
            {"R", {1, 0, 0, 0, 1, 0, 0, 0, 1}},
            {"P", {fx, 0, cx, 0, 0, fy, cy, 0, 0, 0, 1, 0}}};
  return j.dump();
}

json json_schema_of(const json& value, int depth) {
  switch (value.type()) {
    case json::value_t::object: {
      json schema = {{"type", "object"}};
      if (depth <= 0) return schema;
      json props = json::object();
      for (const auto& [key, v] : value.items()) props[key] = json_schema_of(v, depth - 1);
      schema["properties"] = std::move(props);
      return schema;
    }
    case json::value_t::array: {
      json schema = {{"type", "array"}};
      if (depth > 0 && !value.empty()) schema["items"] = json_schema_of(value.front(), depth - 1);
      return schema;
    }
    case json::value_t::string:
      return {{"type", "string"}};
    case json::value_t::boolean:
      return {{"type", "boolean"}};
    case json::value_t::number_integer:
    case json::value_t::number_unsigned:
    case json::value_t::number_float:
      return {{"type", "number"}};
    default:
      return json::object();  // null: anything
  }
}

}  // namespace convoy::live
