// The live channels with Foxglove's well-known schemas (foxglove.Log,
// foxglove.CompressedImage, foxglove.CameraCalibration), whose schemas and JSON messages are
// in record/foxglove_schemas.h (the recording uses them too). And the JSON Schema the server
// derives for a JSON datapack from its first message.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

#include "live/protocol.h"
#include "record/foxglove_schemas.h"

namespace convoy::live {

using record::camera_calibration_json;
using record::compressed_image_json;
using record::log_json;
using record::LogLevel;

ChannelInfo log_channel(const std::string& topic);
ChannelInfo compressed_image_channel(const std::string& topic);
ChannelInfo camera_calibration_channel(const std::string& topic);
// The scene's channels (scene/scene_json.h; schemas in record/scene_schemas.h).
ChannelInfo scene_update_channel(const std::string& topic);
ChannelInfo frame_transforms_channel(const std::string& topic);
ChannelInfo camera_frame_channel(const std::string& topic);

// A JSON Schema describing `value`: its type and, for objects, each property's (arrays by
// their first element), at most `depth` levels deep. Informative: nothing is required.
nlohmann::json json_schema_of(const nlohmann::json& value, int depth = 4);

}  // namespace convoy::live
