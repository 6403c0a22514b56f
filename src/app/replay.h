// A replay of a recorded run (`convoy replay RUN_DIR`): the functions run for real on the
// datapacks the engines gave in the recording, and what they send is compared with what
// they sent then.
//
// No engine starts. Each is a log-backed channel (transport::EngineChannel) that answers
// GetDataPacks with the datapacks recorded at time 0 and the Step that ends at simulated
// time t with those recorded at t (the loop's schedule depends only on simulated time, so
// the reply of each step is found by its end time). A tap (loop::DataPackTap) compares each
// datapack the functions send with the next recorded one of that engine in the same cycle:
// protobuf by bytes, JSON by value (its recorded text), stubs by type and sizes.
//
// The recording is read twice: once whole, to check it (CRCs, a clean end) and learn its
// topics and metadata; then front to back as the loop goes, so memory stays bounded.
#pragma once

#include <cstdint>
#include <deque>
#include <filesystem>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "loop/datapack_tap.h"
#include "record/datapack_codec.h"
#include "record/mcap_reader.h"
#include "transport/engine_channel.h"

namespace convoy::app {

// One recorded datapack.
struct RecordedDataPack {
  uint64_t time_ns = 0, cycle = 0;
  std::string name;
  record::Kind kind = record::Kind::kEmpty;
  std::string type;
  std::string data;
};

struct Mismatch {
  std::string topic;
  uint64_t cycle = 0;
  std::string what;
};

class Replay final : public loop::DataPackTap {
 public:
  // Checks the whole recording and reads its topics and metadata. Throws UserError naming
  // the file on a missing, malformed or cut file (a cut one is accepted with a warning in
  // warnings()).
  explicit Replay(const std::filesystem::path& recording);

  const record::StringMap& metadata() const { return metadata_; }
  // The `convoy_end` metadata: how the live run ended (empty for a cut recording).
  const record::StringMap& end() const { return end_; }
  // Simulated time of the live run's last cycle.
  uint64_t end_time_ns() const { return end_time_ns_; }
  bool record_blobs() const { return record_blobs_; }
  const std::vector<std::string>& warnings() const { return warnings_; }

  // The log-backed channel of engine `name`.
  std::unique_ptr<transport::EngineChannel> channel(const std::string& engine);

  void from_engine(const std::string&, const engine::DataPack&, const datapack::BlobReader&,
                   uint64_t, int64_t) override {}
  void to_engine(const std::string& engine, const engine::DataPack& dp,
                 const datapack::BlobReader& blobs, const loop::LoadedFunction& fn, uint64_t cycle,
                 int64_t time_ns) override;
  // After the loop: recorded datapacks the functions did not send (up to `until_ns`).
  void finish(uint64_t until_ns);

  uint64_t compared() const { return compared_; }
  uint64_t mismatches() const { return mismatches_; }
  const std::vector<Mismatch>& first_mismatches() const { return first_; }
  int placeholders() const { return placeholders_; }
  const std::filesystem::path& path() const { return path_; }

  // For the channels: the datapacks engine `engine` gave at `time_ns` (those of earlier times
  // it did not hand over are dropped). Throws UserError when `wanted` names a datapack the
  // recording never had from that engine.
  std::vector<engine::DataPack> take_from_engine(const std::string& engine, uint64_t time_ns);
  void check_wanted(const std::string& engine, const engine::DataPackId& id) const;

 private:
  struct Topic {
    std::string engine;
    bool to_engine = false;
    std::string name, type;
    record::Kind kind = record::Kind::kEmpty;
  };
  void advance_to(uint64_t time_ns);
  void mismatch(const std::string& topic, uint64_t cycle, std::string what);

  std::filesystem::path path_;
  std::unique_ptr<record::McapReader> reader_;  // the second, streaming pass
  bool reader_done_ = false;
  record::McapMessage peeked_;
  bool has_peeked_ = false;
  std::map<uint16_t, Topic> topics_;
  std::set<std::pair<std::string, std::string>> from_topics_;  // (engine, datapack)
  std::map<std::string, std::deque<RecordedDataPack>> from_, to_;
  record::StringMap metadata_, end_;
  uint64_t end_time_ns_ = 0;
  bool record_blobs_ = false;
  std::vector<std::string> warnings_;
  uint64_t compared_ = 0, mismatches_ = 0;
  std::vector<Mismatch> first_;
  int placeholders_ = 0;
};

}  // namespace convoy::app
