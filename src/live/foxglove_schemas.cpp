#include "live/foxglove_schemas.h"

#include <utility>

#include "record/scene_schemas.h"

namespace convoy::live {

namespace {

using json = nlohmann::json;

ChannelInfo channel(const std::string& topic, record::FoxgloveSchema schema) {
  return {
      0, topic, "json", std::move(schema.name), std::move(schema.data), std::move(schema.encoding)};
}

}  // namespace

ChannelInfo log_channel(const std::string& topic) { return channel(topic, record::log_schema()); }

ChannelInfo compressed_image_channel(const std::string& topic) {
  return channel(topic, record::compressed_image_schema());
}

ChannelInfo camera_calibration_channel(const std::string& topic) {
  return channel(topic, record::camera_calibration_schema());
}

ChannelInfo scene_update_channel(const std::string& topic) {
  return channel(topic, record::scene_update_schema());
}

ChannelInfo frame_transforms_channel(const std::string& topic) {
  return channel(topic, record::frame_transforms_schema());
}

ChannelInfo camera_frame_channel(const std::string& topic) {
  return channel(topic, record::camera_frame_schema());
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
