#include "record/foxglove_schemas.h"

#include <cmath>
#include <nlohmann/json.hpp>

#include "record/datapack_codec.h"

namespace convoy::record {

namespace {

using json = nlohmann::json;

const json& time_schema() {
  static const json kTime = {
      {"type", "object"},
      {"title", "time"},
      {"properties",
       {{"sec", {{"type", "integer"}, {"minimum", 0}}},
        {"nsec", {{"type", "integer"}, {"minimum", 0}, {"maximum", 999999999}}}}}};
  return kTime;
}

json stamp(uint64_t ns) { return {{"sec", ns / 1000000000u}, {"nsec", ns % 1000000000u}}; }

json numbers(int n) {
  json a = {{"type", "array"}, {"items", {{"type", "number"}}}};
  if (n > 0) a["minItems"] = a["maxItems"] = n;
  return a;
}

FoxgloveSchema json_schema(const char* name, json properties) {
  json schema = {{"title", name}, {"type", "object"}, {"properties", std::move(properties)}};
  return {name, "jsonschema", schema.dump()};
}

}  // namespace

FoxgloveSchema log_schema() {
  return json_schema("foxglove.Log",
                     {{"timestamp", time_schema()},
                      {"level", {{"type", "integer"}, {"enum", {0, 1, 2, 3, 4, 5}}}},
                      {"message", {{"type", "string"}}},
                      {"name", {{"type", "string"}}},
                      {"file", {{"type", "string"}}},
                      {"line", {{"type", "integer"}, {"minimum", 0}}}});
}

FoxgloveSchema compressed_image_schema() {
  return json_schema("foxglove.CompressedImage",
                     {{"timestamp", time_schema()},
                      {"frame_id", {{"type", "string"}}},
                      {"data", {{"type", "string"}, {"contentEncoding", "base64"}}},
                      {"format", {{"type", "string"}}}});
}

FoxgloveSchema camera_calibration_schema() {
  return json_schema("foxglove.CameraCalibration",
                     {{"timestamp", time_schema()},
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
  out += base64_encode(jpeg);
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

}  // namespace convoy::record
