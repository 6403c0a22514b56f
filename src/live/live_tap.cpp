#include "live/live_tap.h"

#include <chrono>

#include "datapack/camera.h"
#include "datapack/registry.h"
#include "record/datapack_codec.h"
#include "scene/scene_json.h"

namespace convoy::live {

namespace {

constexpr const char* kCameraType = "convoy.data.Camera";

std::shared_ptr<const std::string> shared(std::string s) {
  return std::make_shared<const std::string>(std::move(s));
}

}  // namespace

LiveTap::LiveTap(LiveServer& server, TapOptions options)
    : server_(server),
      options_(options),
      scene_(options.scene),
      scene_pacer_(options.scene_hz),
      encoder_(server, options.jpeg_quality, options.camera_hfov) {
  log_channel_ = server_.add_channel(log_channel(kLogTopic), options_.log_lines_kept);
  if (options_.map) {
    const uint32_t map = server_.add_channel(scene_update_channel(scene::kMapTopic), 1);
    server_.publish(map, 0, shared(scene::map_update_json(*options_.map, 0)));
  }
  if (options_.scene_hz > 0) {
    scene_channel_ = server_.add_channel(scene_update_channel(scene::kSceneTopic));
    transforms_channel_ = server_.add_channel(frame_transforms_channel(scene::kTransformsTopic));
  }
  frames_channel_ = server_.add_channel(camera_frame_channel(scene::kFramesTopic));
}

void LiveTap::from_engine(const std::string& engine, const engine::DataPack& dp,
                          const datapack::BlobReader& blobs, uint64_t, int64_t time_ns) {
  tap(engine, dp, blobs, false, time_ns);
}

void LiveTap::to_engine(const std::string& engine, const engine::DataPack& dp,
                        const datapack::BlobReader& blobs, const loop::LoadedFunction&, uint64_t,
                        int64_t time_ns) {
  tap(engine, dp, blobs, true, time_ns);
}

void LiveTap::log(LogLevel level, const std::string& line) {
  const auto t = static_cast<uint64_t>(time_ns_.load());
  server_.publish(log_channel_, t, shared(log_json(t, level, "convoy", line)));
}

void LiveTap::tap(const std::string& engine, const engine::DataPack& dp,
                  const datapack::BlobReader& blobs, bool to_engine, int64_t time_ns) {
  time_ns_.store(time_ns);
  server_.publish_time(static_cast<uint64_t>(time_ns));
  if (!to_engine && options_.scene_hz > 0) scene(engine, dp, blobs, time_ns);
  // Nothing to show (a datapack not produced yet); a channel of its own would only double
  // the topic of the real one.
  if (dp.payload_case() == engine::DataPack::PAYLOAD_NOT_SET) return;
  try {
    const uint32_t id = channel(engine, dp, blobs, to_engine);
    if (server_.has_subscribers(id)) {
      server_.publish(id, static_cast<uint64_t>(time_ns),
                      shared(record::encode(dp, blobs, /*with_blobs=*/false).data));
      ++encoded_;
    }
    if (!to_engine && dp.payload_case() == engine::DataPack::kProto &&
        dp.proto().type_name() == kCameraType && options_.camera_hz > 0)
      camera(engine + "/" + dp.id().name(), dp, blobs, time_ns);
  } catch (const std::exception& e) {
    // A datapack the viewers cannot see must not end a run that works without them.
    if (skipped_++ == 0) first_skip_ = e.what();
  }
}

uint32_t LiveTap::channel(const std::string& engine, const engine::DataPack& dp,
                          const datapack::BlobReader& blobs, bool to_engine) {
  using record::Kind;
  const Kind kind = record::kind_of(dp, false);
  const std::string type = kind == Kind::kProtobuf ? dp.proto().type_name() : dp.id().type();
  auto key = std::make_tuple(engine, dp.id().name(), to_engine, static_cast<int>(kind), type);
  if (auto it = channels_.find(key); it != channels_.end()) return it->second;
  ChannelInfo info;
  info.topic = engine + "/" + dp.id().name() + (to_engine ? "/in" : "");
  if (kind == Kind::kProtobuf) {
    info.encoding = "protobuf";
    info.schema_name = type;
    info.schema_encoding = "protobuf";
    info.schema = record::base64_encode(datapack::Registry::global().file_descriptor_set(type));
  } else {
    info.encoding = "json";
    info.schema_encoding = "jsonschema";
    nlohmann::json schema = {{"type", "object"}};
    if (kind == Kind::kJson) {
      info.schema_name = "convoy.JsonDataPack";
      // The first message shows the shape (encoded once, subscribed or not).
      const auto first = nlohmann::json::parse(record::encode(dp, blobs, false).data, nullptr,
                                               /*allow_exceptions=*/false);
      if (!first.is_discarded()) schema = json_schema_of(first);
    } else {
      info.schema_name = kind == Kind::kStub ? "convoy.BlobStub" : "convoy.EmptyDataPack";
    }
    schema["title"] = info.schema_name;
    schema["description"] = "a Convoy datapack as recorded (docs/recording.md)";
    info.schema = schema.dump();
  }
  const uint32_t id = server_.add_channel(std::move(info));
  channels_.emplace(std::move(key), id);
  return id;
}

void LiveTap::scene(const std::string& engine, const engine::DataPack& dp,
                    const datapack::BlobReader& blobs, int64_t time_ns) {
  if (const auto due = scene_pacer_.due(time_ns, !scene_.empty())) {
    const auto t = static_cast<uint64_t>(*due);
    if (server_.has_subscribers(scene_channel_))
      server_.publish(scene_channel_, t,
                      shared(scene::scene_update_json(scene_, options_.map.get(), t)));
    if (server_.has_subscribers(transforms_channel_))
      server_.publish(transforms_channel_, t, shared(scene::frame_transforms_json(scene_, t)));
    // A client that subscribes later never had the entities that left.
    scene_.clear_deleted();
  }
  scene_.ingest(engine, datapack::View(dp, blobs), time_ns);
}

void LiveTap::camera(const std::string& topic, const engine::DataPack& dp,
                     const datapack::BlobReader& blobs, int64_t time_ns) {
  auto [it, added] = cameras_.try_emplace(topic);
  Camera& cam = it->second;
  if (added) {
    cam.image = server_.add_channel(compressed_image_channel(topic + "/image"));
    cam.calibration = server_.add_channel(camera_calibration_channel(topic + "/calibration"), 1);
  }
  const auto period = static_cast<int64_t>(1e9 / options_.camera_hz);
  if (cam.last_ns >= 0 && time_ns - cam.last_ns < period) return;
  const bool want_image = server_.has_subscribers(cam.image);
  if (!want_image && !server_.has_subscribers(cam.calibration)) return;
  const datapack::CameraImage img = datapack::read_camera(datapack::View(dp, blobs));
  if (img.width == 0 || img.height == 0) return;
  cam.last_ns = time_ns;
  Frame f;
  f.image_channel = cam.image;
  f.calibration_channel = cam.calibration;
  f.want_image = want_image;
  f.frame_note_channel = frames_channel_;
  f.want_frame_note = want_image && server_.has_subscribers(frames_channel_);
  f.wall_ms =
      std::chrono::duration<double, std::milli>(std::chrono::system_clock::now().time_since_epoch())
          .count();
  f.frame_id = topic;
  f.time_ns = static_cast<uint64_t>(time_ns);
  f.width = img.width;
  f.height = img.height;
  f.channels = img.depth;
  f.pixels.assign(img.pixels.data(), img.pixels.size());
  encoder_.submit(std::move(f));
}

}  // namespace convoy::live
