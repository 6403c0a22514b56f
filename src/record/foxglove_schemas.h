// Foxglove's well-known message schemas in their JSON encoding (timestamps as {sec, nsec},
// bytes as base64), with JSON Schemas written for them: foxglove.Log,
// foxglove.CompressedImage, foxglove.CameraCalibration. Shared by the live server's channels
// (src/live) and the recording's camera channels (record::Recorder), so that Foxglove and
// Lichtblick show both the same way.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace convoy::record {

// A schema as MCAP and the Foxglove WebSocket protocol carry it.
struct FoxgloveSchema {
  std::string name;      // e.g. "foxglove.CompressedImage"
  std::string encoding;  // "jsonschema"
  std::string data;      // the JSON Schema
};

FoxgloveSchema log_schema();
FoxgloveSchema compressed_image_schema();
FoxgloveSchema camera_calibration_schema();

// foxglove.Log levels.
enum class LogLevel { kDebug = 1, kInfo = 2, kWarning = 3, kError = 4, kFatal = 5 };

std::string log_json(uint64_t time_ns, LogLevel level, std::string_view name,
                     std::string_view message);
std::string compressed_image_json(uint64_t time_ns, std::string_view frame_id,
                                  std::string_view jpeg);
// A pinhole camera without distortion whose horizontal field of view is `hfov` radians.
std::string camera_calibration_json(uint64_t time_ns, std::string_view frame_id, uint32_t width,
                                    uint32_t height, double hfov);

}  // namespace convoy::record
