// The coordinator's side of the live server: a loop::DataPackTap that makes every datapack
// crossing the loop a channel of the server, in the form the recording gives it
// (record/datapack_codec.h: JSON datapacks as JSON with a JSON Schema derived from their first
// message, protobuf ones as protobuf with their FileDescriptorSet, blobs as small stubs).
// Topics are the recording's: `<engine>/<datapack>` from an engine, `<engine>/<datapack>/in`
// sent to it by a function. A datapack is encoded only when a client is subscribed to its
// channel. Empty datapacks (not produced yet) are left out.
//
// A camera frame (convoy.data.Camera) also gives `<engine>/<datapack>/image`
// (foxglove.CompressedImage, JPEG, at most `camera_hz` frames per simulated second, encoded on
// FrameEncoder's thread) and `<engine>/<datapack>/calibration` (foxglove.CameraCalibration).
// log() publishes a line of the coordinator's log on `/convoy/log` (foxglove.Log; the last
// lines are kept for a viewer that connects late). The simulated time goes to every client.
//
// The scene (scene/scene_json.h): `/convoy/map` once, kept for every client that subscribes
// later, when a map is given; `/convoy/scene` and `/convoy/transforms` at most `scene_hz` per
// simulated second, built only while someone subscribes to them (the road users are taken in
// all the time, for the ego's trail); `/convoy/frames` notes each camera frame published with
// the wall-clock time its datapack reached the tap (for latency measurements).
#pragma once

#include <atomic>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <tuple>

#include "live/foxglove_schemas.h"
#include "live/frame_encoder.h"
#include "live/server.h"
#include "loop/datapack_tap.h"
#include "scene/scene_map.h"
#include "scene/scene_state.h"

namespace convoy::live {

struct TapOptions {
  double camera_hz = 10;  // JPEG frames per simulated second and camera (0: none)
  int jpeg_quality = 80;
  double camera_hfov = 1.047;  // the calibration's field of view (rad): the datapack has none
  size_t log_lines_kept = 500;
  double scene_hz = 10;  // /convoy/scene and /convoy/transforms per simulated second (0: none)
  std::shared_ptr<const scene::SceneMap> map;  // null: no /convoy/map
  scene::SceneOptions scene;
};

inline constexpr const char* kLogTopic = "/convoy/log";

class LiveTap final : public loop::DataPackTap {
 public:
  LiveTap(LiveServer& server, TapOptions options);

  void from_engine(const std::string& engine, const engine::DataPack& dp,
                   const datapack::BlobReader& blobs, uint64_t cycle, int64_t time_ns) override;
  void to_engine(const std::string& engine, const engine::DataPack& dp,
                 const datapack::BlobReader& blobs, const loop::LoadedFunction& fn, uint64_t cycle,
                 int64_t time_ns) override;
  // A log line, at the last simulated time seen. Any thread.
  void log(LogLevel level, const std::string& line);

  uint64_t channels() const { return channels_.size(); }
  uint64_t encoded() const { return encoded_; }  // datapacks encoded for subscribers
  uint64_t skipped() const { return skipped_; }  // datapacks that could not be encoded
  const std::string& first_skip() const { return first_skip_; }
  const FrameEncoder& frames() const { return encoder_; }

 private:
  void tap(const std::string& engine, const engine::DataPack& dp, const datapack::BlobReader& blobs,
           bool to_engine, int64_t time_ns);
  uint32_t channel(const std::string& engine, const engine::DataPack& dp,
                   const datapack::BlobReader& blobs, bool to_engine);
  // The scene before a datapack of `time_ns` from an engine is taken in (when an update is
  // due and wanted), then the datapack.
  void scene(const std::string& engine, const engine::DataPack& dp,
             const datapack::BlobReader& blobs, int64_t time_ns);
  void camera(const std::string& topic, const engine::DataPack& dp,
              const datapack::BlobReader& blobs, int64_t time_ns);

  struct Camera {
    uint32_t image = 0, calibration = 0;
    int64_t last_ns = -1;
  };
  LiveServer& server_;
  TapOptions options_;
  uint32_t log_channel_ = 0;
  uint32_t scene_channel_ = 0, transforms_channel_ = 0, frames_channel_ = 0;
  scene::SceneState scene_;
  scene::ScenePacer scene_pacer_;
  std::atomic<int64_t> time_ns_{0};
  std::map<std::tuple<std::string, std::string, bool, int, std::string>, uint32_t> channels_;
  std::map<std::string, Camera> cameras_;
  uint64_t encoded_ = 0, skipped_ = 0;
  std::string first_skip_;
  FrameEncoder encoder_;  // last: its thread stops first
};

}  // namespace convoy::live
