#include "live/foxglove_schemas.h"

#include <gtest/gtest.h>

#include "live/jpeg.h"
#include "record/datapack_codec.h"

namespace convoy::live {
namespace {

using json = nlohmann::json;

TEST(FoxgloveSchemas, ChannelsNameTheWellKnownSchemas) {
  for (const auto& [c, name] :
       {std::pair{log_channel("/convoy/log"), "foxglove.Log"},
        {compressed_image_channel("c/image"), "foxglove.CompressedImage"},
        {camera_calibration_channel("c/cal"), "foxglove.CameraCalibration"}}) {
    EXPECT_EQ(c.schema_name, name);
    EXPECT_EQ(c.encoding, "json");
    EXPECT_EQ(c.schema_encoding, "jsonschema");
    const auto schema = json::parse(c.schema);
    EXPECT_EQ(schema["type"], "object");
    EXPECT_TRUE(schema["properties"].contains("timestamp")) << name;
  }
}

TEST(FoxgloveSchemas, LogMessage) {
  const auto j = json::parse(log_json(2500000001ull, LogLevel::kWarning, "convoy", "warning: x"));
  EXPECT_EQ(j["timestamp"]["sec"], 2);
  EXPECT_EQ(j["timestamp"]["nsec"], 500000001);
  EXPECT_EQ(j["level"], 3);
  EXPECT_EQ(j["name"], "convoy");
  EXPECT_EQ(j["message"], "warning: x");
}

TEST(FoxgloveSchemas, CompressedImageCarriesTheJpegInBase64) {
  std::string pixels(8 * 4 * 3, '\x80');
  const std::string jpeg = encode_jpeg(pixels, 8, 4, 3, 80);
  const auto j = json::parse(compressed_image_json(1000, "cam", jpeg));
  EXPECT_EQ(j["format"], "jpeg");
  EXPECT_EQ(j["frame_id"], "cam");
  EXPECT_EQ(record::base64_decode(j["data"].get<std::string>()), jpeg);
}

TEST(FoxgloveSchemas, CalibrationOfAPinholeCamera) {
  const auto j = json::parse(camera_calibration_json(0, "cam", 640, 480, 1.5707963267948966));
  EXPECT_EQ(j["width"], 640);
  EXPECT_EQ(j["K"].size(), 9u);
  EXPECT_NEAR(j["K"][0].get<double>(), 320.0, 1e-9);  // 90 degrees: fx = width / 2
  EXPECT_NEAR(j["K"][2].get<double>(), 320.0, 1e-9);
  EXPECT_NEAR(j["K"][5].get<double>(), 240.0, 1e-9);
  EXPECT_EQ(j["P"].size(), 12u);
  EXPECT_EQ(j["R"].size(), 9u);
}

TEST(Jpeg, EncodesGreyRgbAndRgbaAndRefusesWrongSizes) {
  for (uint32_t channels : {1u, 3u, 4u}) {
    std::string pixels(16 * 8 * channels, '\0');
    for (size_t i = 0; i < pixels.size(); ++i) pixels[i] = static_cast<char>(i * 7);
    const std::string jpeg = encode_jpeg(pixels, 16, 8, channels, 90);
    ASSERT_GT(jpeg.size(), 100u);
    EXPECT_EQ(static_cast<uint8_t>(jpeg[0]), 0xff);
    EXPECT_EQ(static_cast<uint8_t>(jpeg[1]), 0xd8);
    EXPECT_EQ(static_cast<uint8_t>(jpeg[jpeg.size() - 2]), 0xff);
    EXPECT_EQ(static_cast<uint8_t>(jpeg[jpeg.size() - 1]), 0xd9);
  }
  EXPECT_THROW(encode_jpeg(std::string(10, '\0'), 16, 8, 3, 90), std::invalid_argument);
  EXPECT_THROW(encode_jpeg(std::string(16 * 8 * 2, '\0'), 16, 8, 2, 90), std::invalid_argument);
}

TEST(FoxgloveSchemas, SchemaDerivedFromAJsonValue) {
  const auto s = json_schema_of(json::parse(R"({"x": 1.5, "name": "car", "ok": true,
                                                "boxes": [{"cls": 2}], "none": null})"));
  EXPECT_EQ(s["type"], "object");
  EXPECT_EQ(s["properties"]["x"]["type"], "number");
  EXPECT_EQ(s["properties"]["name"]["type"], "string");
  EXPECT_EQ(s["properties"]["ok"]["type"], "boolean");
  EXPECT_EQ(s["properties"]["boxes"]["type"], "array");
  EXPECT_EQ(s["properties"]["boxes"]["items"]["properties"]["cls"]["type"], "number");
  EXPECT_EQ(s["properties"]["none"], json::object());
  EXPECT_FALSE(s.contains("required"));
}

}  // namespace
}  // namespace convoy::live
