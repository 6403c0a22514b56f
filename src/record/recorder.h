// Records the datapacks that cross the coordinator into an MCAP file (the run folder's
// recording.mcap), as `convoy run --record` asks.
//
// Topics: `<engine>/<datapack>` for what the loop takes from an engine for the functions,
// `<engine>/<datapack>/in` for what the functions send to it. log_time and publish_time are
// the simulated time of the loop cycle in ns, the message's sequence is the loop cycle. The
// encodings are those of record/datapack_codec.h: JSON datapacks as JSON, protobuf ones as
// protobuf with their FileDescriptorSet, blobs (camera frames) as stubs unless
// `record_blobs`. A Metadata record `convoy` holds what a replay needs (the effective config,
// Convoy's version); `convoy_end` how the run ended.
//
// For viewers (Foxglove, Lichtblick), each camera (`convoy.data.Camera` taken from an engine)
// also gives `<engine>/<datapack>/image` as `foxglove.CompressedImage` (JPEG) and
// `<engine>/<datapack>/calibration` as `foxglove.CameraCalibration`, the live server's
// channels (record/foxglove_schemas.h): every frame when blobs are recorded, else at
// `camera_hz` per simulated second. Chunks are compressed with zstd.
//
// The scene (scene/scene_json.h): `/convoy/map` once at the start when a map is given,
// `/convoy/scene` and `/convoy/transforms` at `scene_hz` per simulated second from the road
// users, signals and route of the datapacks taken from engines, so that a viewer's 3D panel
// shows the run.
//
// A write that fails (disk full) ends the run: the next datapack the loop hands over throws
// convoy::UserError ("no space left writing PATH: ..."; exit 2); the file keeps its whole
// chunks.
#pragma once

#include <filesystem>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <tuple>

#include "loop/datapack_tap.h"
#include "record/datapack_codec.h"
#include "record/foxglove_schemas.h"
#include "record/mcap_writer.h"
#include "scene/scene_map.h"
#include "scene/scene_state.h"

namespace convoy::record {

inline constexpr const char* kRecordingFile = "recording.mcap";
inline constexpr const char* kRecordingFormat = "convoy-recording-1";

struct RecorderOptions {
  McapWriterOptions mcap;      // chunk size and compression
  double camera_hz = 1;        // JPEG frames per simulated second without blobs (0: none)
  int jpeg_quality = 80;       // as the live server's
  double camera_hfov = 1.047;  // the calibration's field of view (rad): the datapack has none
  double scene_hz = 10;  // /convoy/scene and /convoy/transforms per simulated second (0: none)
  std::shared_ptr<const scene::SceneMap> map;  // null: no /convoy/map
  scene::SceneOptions scene;
};

class Recorder final : public loop::DataPackTap {
 public:
  // Creates `path` and writes the header and the `convoy` metadata. Throws std::runtime_error.
  Recorder(const std::filesystem::path& path, bool record_blobs, const StringMap& metadata,
           const RecorderOptions& options = {});
  ~Recorder() override;

  void from_engine(const std::string& engine, const engine::DataPack& dp,
                   const datapack::BlobReader& blobs, uint64_t cycle, int64_t time_ns) override;
  void to_engine(const std::string& engine, const engine::DataPack& dp,
                 const datapack::BlobReader& blobs, const loop::LoadedFunction& fn, uint64_t cycle,
                 int64_t time_ns) override;

  // What the run's functions publish for viewers (python/live_module.h: convoy_live.publish):
  // /convoy/metrics, merged into the latest summary fields, which are written with "time_ns";
  // /convoy/infractions, one message each. Channels marked {"viewer": "metrics"}: a replay
  // leaves them out. Returns false for another topic or a message that is not a JSON object.
  bool viewer_json(const std::string& topic, const std::string& json, int64_t time_ns);

  // Writes the `convoy_end` metadata and finishes the file. Returns a write error not
  // thrown already, or "".
  std::string finish(const StringMap& end);
  // What the file holds: messages in whole chunks, bytes.
  uint64_t messages() const { return writer_.file_messages(); }
  uint64_t bytes() const { return writer_.file_bytes(); }
  const std::filesystem::path& path() const { return writer_.path(); }
  // Datapacks that could not be encoded (left out), and why the first one could not.
  uint64_t skipped() const { return skipped_; }
  const std::string& first_skip() const { return first_skip_; }
  uint64_t camera_frames() const { return camera_frames_; }

 private:
  void write(const std::string& engine, const engine::DataPack& dp,
             const datapack::BlobReader& blobs, bool to_engine, const std::string& function,
             uint64_t cycle, int64_t time_ns);
  uint16_t channel(const std::string& engine, const std::string& name, bool to_engine,
                   const Encoded& enc);
  // The camera's JPEG and calibration, when its period has passed.
  void camera(const std::string& topic, const engine::DataPack& dp,
              const datapack::BlobReader& blobs, uint64_t cycle, int64_t time_ns);
  uint16_t foxglove_schema(const FoxgloveSchema& schema);
  // Throws convoy::UserError once, when the writer has failed.
  void check_writer();
  // The scene before a datapack of `time_ns` is taken in (when an update is due), then the
  // datapack.
  void scene(const std::string& engine, const engine::DataPack& dp,
             const datapack::BlobReader& blobs, uint64_t cycle, int64_t time_ns);

  struct Camera {
    uint16_t image = 0, calibration = 0;
    int64_t last_ns = -1;
  };

  McapWriter writer_;
  bool write_error_thrown_ = false;
  bool record_blobs_;
  RecorderOptions options_;
  std::map<std::string, Camera> cameras_;  // by topic
  uint64_t camera_frames_ = 0;
  uint64_t skipped_ = 0;
  std::string first_skip_;
  scene::SceneState scene_;
  scene::ScenePacer scene_pacer_;
  uint16_t scene_channel_ = 0, transforms_channel_ = 0;
  bool scene_channels_ = false;
  uint64_t scene_cycle_ = 0;
  std::map<std::string, uint16_t> viewer_channels_;  // by topic
  std::map<std::string, uint32_t> viewer_sequence_;  // by topic
  nlohmann::json latest_metrics_ = nlohmann::json::object();
  std::map<std::string, uint16_t> schemas_;  // "kind\0type" -> schema id
  std::map<std::tuple<std::string, std::string, bool, int, std::string>, uint16_t> channels_;
};

}  // namespace convoy::record
