#include "record/recorder.h"

#include <algorithm>

#include "core/error.h"
#include "datapack/camera.h"
#include "datapack/registry.h"
#include "record/datapack_codec.h"
#include "record/jpeg.h"
#include "record/scene_schemas.h"
#include "scene/scene_json.h"

namespace convoy::record {

namespace {
// JSON messages get a permissive JSON Schema, so that viewers that want one (Foxglove's
// panels) have it; the spec allows none for json.
constexpr const char* kJsonSchema =
    R"js({"type":"object","description":"a Convoy JSON datapack (docs/recording.md)"})js";
constexpr const char* kCameraType = "convoy.data.Camera";
// The scene's channels say they are for viewers (a replay leaves them out, as the cameras').
const StringMap kViewer = {{"viewer", "scene"}};
}  // namespace

Recorder::Recorder(const std::filesystem::path& path, bool record_blobs, const StringMap& metadata,
                   const RecorderOptions& options)
    : record_blobs_(record_blobs),
      options_(options),
      scene_(options.scene),
      scene_pacer_(options.scene_hz) {
  writer_.open(path, std::string("convoy ") + metadata.at("convoy_version"), options.mcap);
  writer_.write_metadata("convoy", metadata);
  if (options_.map) {
    const uint16_t ch =
        writer_.add_channel(scene::kMapTopic, "json", foxglove_schema(scene_update_schema()),
                            {{"viewer", "scene"}, {"source", options_.map->source}});
    writer_.write_message(ch, 0, 0, 0, scene::map_update_json(*options_.map, 0));
  }
}

Recorder::~Recorder() { writer_.close(); }

uint16_t Recorder::channel(const std::string& engine, const std::string& name, bool to_engine,
                           const Encoded& enc) {
  auto key = std::make_tuple(engine, name, to_engine, static_cast<int>(enc.kind), enc.type);
  if (auto it = channels_.find(key); it != channels_.end()) return it->second;
  std::string schema_key = std::string(kind_name(enc.kind)) + '\0' +
                           (enc.kind == Kind::kProtobuf ? enc.type : std::string());
  uint16_t schema = 0;
  if (auto it = schemas_.find(schema_key); it != schemas_.end()) {
    schema = it->second;
  } else {
    switch (enc.kind) {
      case Kind::kProtobuf:
        schema = writer_.add_schema(enc.type, "protobuf",
                                    datapack::Registry::global().file_descriptor_set(enc.type));
        break;
      case Kind::kJson:
        schema = writer_.add_schema("convoy.JsonDataPack", "jsonschema", kJsonSchema);
        break;
      case Kind::kStub:
        schema = writer_.add_schema("convoy.BlobStub", "jsonschema", kJsonSchema);
        break;
      case Kind::kEmpty:
        schema = writer_.add_schema("convoy.EmptyDataPack", "jsonschema", kJsonSchema);
        break;
    }
    schemas_[schema_key] = schema;
  }
  StringMap meta = {{"engine", engine},
                    {"datapack", name},
                    {"type", enc.type},
                    {"kind", kind_name(enc.kind)},
                    {"direction", to_engine ? "to_engine" : "from_engine"}};
  std::string topic = engine + "/" + name + (to_engine ? "/in" : "");
  const std::string encoding = enc.kind == Kind::kProtobuf ? "protobuf" : "json";
  uint16_t id = writer_.add_channel(topic, encoding, schema, meta);
  channels_.emplace(std::move(key), id);
  return id;
}

void Recorder::write(const std::string& engine, const engine::DataPack& dp,
                     const datapack::BlobReader& blobs, bool to_engine, const std::string&,
                     uint64_t cycle, int64_t time_ns) {
  if (!to_engine) scene(engine, dp, blobs, cycle, time_ns);
  Encoded enc;
  try {
    enc = encode(dp, blobs, record_blobs_);
  } catch (const std::exception& e) {
    // A datapack the recording cannot hold must not end a run that works without it.
    if (skipped_++ == 0) first_skip_ = e.what();
    return;
  }
  const uint16_t ch = channel(engine, dp.id().name(), to_engine, enc);
  const auto t = static_cast<uint64_t>(time_ns);
  writer_.write_message(ch, static_cast<uint32_t>(cycle), t, t, enc.data);
  if (!to_engine && dp.payload_case() == engine::DataPack::kProto &&
      dp.proto().type_name() == kCameraType) {
    try {
      camera(engine + "/" + dp.id().name(), dp, blobs, cycle, time_ns);
    } catch (const std::exception& e) {
      if (skipped_++ == 0) first_skip_ = e.what();
    }
  }
}

uint16_t Recorder::foxglove_schema(const FoxgloveSchema& schema) {
  const std::string key = std::string("foxglove") + '\0' + schema.name;
  if (auto it = schemas_.find(key); it != schemas_.end()) return it->second;
  const uint16_t id = writer_.add_schema(schema.name, schema.encoding, schema.data);
  schemas_[key] = id;
  return id;
}

void Recorder::camera(const std::string& topic, const engine::DataPack& dp,
                      const datapack::BlobReader& blobs, uint64_t cycle, int64_t time_ns) {
  if (!record_blobs_ && options_.camera_hz <= 0) return;
  auto [it, added] = cameras_.try_emplace(topic);
  Camera& cam = it->second;
  if (!record_blobs_) {
    const auto period = static_cast<int64_t>(1e9 / options_.camera_hz);
    if (cam.last_ns >= 0 && time_ns - cam.last_ns < period) return;
  }
  const datapack::CameraImage img = datapack::read_camera(datapack::View(dp, blobs));
  if (img.width == 0 || img.height == 0) return;
  if (added) {
    const StringMap meta = {{"camera", topic}};
    cam.image = writer_.add_channel(topic + "/image", "json",
                                    foxglove_schema(compressed_image_schema()), meta);
    cam.calibration = writer_.add_channel(topic + "/calibration", "json",
                                          foxglove_schema(camera_calibration_schema()), meta);
  }
  cam.last_ns = time_ns;
  const auto t = static_cast<uint64_t>(time_ns);
  const auto seq = static_cast<uint32_t>(cycle);
  const std::string jpeg =
      encode_jpeg(img.pixels, img.width, img.height, img.depth, options_.jpeg_quality);
  writer_.write_message(cam.image, seq, t, t, compressed_image_json(t, topic, jpeg));
  writer_.write_message(
      cam.calibration, seq, t, t,
      camera_calibration_json(t, topic, img.width, img.height, options_.camera_hfov));
  ++camera_frames_;
}

void Recorder::scene(const std::string& engine, const engine::DataPack& dp,
                     const datapack::BlobReader& blobs, uint64_t cycle, int64_t time_ns) {
  if (const auto due = scene_pacer_.due(time_ns, !scene_.empty())) {
    if (!scene_channels_) {
      scene_channels_ = true;
      scene_channel_ = writer_.add_channel(scene::kSceneTopic, "json",
                                           foxglove_schema(scene_update_schema()), kViewer);
      transforms_channel_ = writer_.add_channel(
          scene::kTransformsTopic, "json", foxglove_schema(frame_transforms_schema()), kViewer);
    }
    const auto t = static_cast<uint64_t>(*due);
    const auto seq = static_cast<uint32_t>(scene_cycle_);
    writer_.write_message(scene_channel_, seq, t, t,
                          scene::scene_update_json(scene_, options_.map.get(), t));
    writer_.write_message(transforms_channel_, seq, t, t, scene::frame_transforms_json(scene_, t));
    scene_.clear_deleted();
  }
  scene_cycle_ = cycle;
  scene_.ingest(engine, datapack::View(dp, blobs), time_ns);
}

void Recorder::check_writer() {
  if (writer_.error().empty() || write_error_thrown_) return;
  write_error_thrown_ = true;
  throw UserError(writer_.error() + ": the run stops here; the recording keeps its first " +
                  std::to_string(writer_.file_messages()) + " messages (" +
                  std::to_string(writer_.file_bytes()) +
                  " bytes, up to its last whole chunk, without its summary)");
}

void Recorder::from_engine(const std::string& engine, const engine::DataPack& dp,
                           const datapack::BlobReader& blobs, uint64_t cycle, int64_t time_ns) {
  write(engine, dp, blobs, false, "", cycle, time_ns);
  check_writer();
}

void Recorder::to_engine(const std::string& engine, const engine::DataPack& dp,
                         const datapack::BlobReader& blobs, const loop::LoadedFunction& fn,
                         uint64_t cycle, int64_t time_ns) {
  write(engine, dp, blobs, true, fn.name, cycle, time_ns);
  check_writer();
}

bool Recorder::viewer_json(const std::string& topic, const std::string& json, int64_t time_ns) {
  const bool metrics = topic == "/convoy/metrics";
  if (!writer_.is_open() || (!metrics && topic != "/convoy/infractions")) return false;
  nlohmann::json msg = nlohmann::json::parse(json, nullptr, false);
  if (!msg.is_object()) return false;
  auto [it, added] = viewer_channels_.emplace(topic, 0);
  if (added) {
    const FoxgloveSchema schema{metrics ? "convoy.Metrics" : "convoy.Infraction", "jsonschema",
                                kJsonSchema};
    it->second =
        writer_.add_channel(topic, "json", foxglove_schema(schema), {{"viewer", "metrics"}});
  }
  std::string text = json;
  if (metrics) {
    latest_metrics_.update(msg);
    latest_metrics_["time_ns"] = time_ns;
    text = latest_metrics_.dump();
  }
  const auto t = static_cast<uint64_t>(std::max<int64_t>(time_ns, 0));
  writer_.write_message(it->second, viewer_sequence_[topic]++, t, t, text);
  return true;
}

std::string Recorder::finish(const StringMap& end) {
  if (!writer_.is_open()) return "";
  writer_.write_metadata("convoy_end", end);
  const std::string error = writer_.close();
  return write_error_thrown_ ? "" : error;
}

}  // namespace convoy::record
