// Foxglove's well-known message schemas in their JSON encoding (timestamps as {sec, nsec},
// bytes as base64), with their JSON Schemas, for the live channels: foxglove.Log,
// foxglove.CompressedImage, foxglove.CameraCalibration. And the JSON Schema the server
// derives for a JSON datapack from its first message.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

#include "live/protocol.h"

namespace convoy::live {

// foxglove.Log levels.
enum class LogLevel { kDebug = 1, kInfo = 2, kWarning = 3, kError = 4, kFatal = 5 };

ChannelInfo log_channel(const std::string& topic);
ChannelInfo compressed_image_channel(const std::string& topic);
ChannelInfo camera_calibration_channel(const std::string& topic);

std::string log_json(uint64_t time_ns, LogLevel level, std::string_view name,
                     std::string_view message);
std::string compressed_image_json(uint64_t time_ns, std::string_view frame_id,
                                  std::string_view jpeg);
// A pinhole camera without distortion whose horizontal field of view is `hfov` radians.
std::string camera_calibration_json(uint64_t time_ns, std::string_view frame_id, uint32_t width,
                                    uint32_t height, double hfov);

// A JSON Schema describing `value`: its type and, for objects, each property's (arrays by
// their first element), at most `depth` levels deep. Informative: nothing is required.
nlohmann::json json_schema_of(const nlohmann::json& value, int depth = 4);

}  // namespace convoy::live
