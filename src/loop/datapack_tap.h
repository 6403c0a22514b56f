// Sees every datapack that crosses the coordinator's loop: the recorder (record/recorder.h)
// writes them into the run's recording, a replay (app/replay.h) compares them with it.
// Without a tap the loop pays one null-pointer test per datapack.
#pragma once

#include <cstdint>

#include "convoy/engine.pb.h"
#include "datapack/blobs.h"
#include "loop/function_runner.h"

namespace convoy::loop {

class DataPackTap {
 public:
  virtual ~DataPackTap() = default;
  // A datapack the loop took from `engine` for the functions: fetched after Initialize (cycle
  // 0, time 0), or in a Step reply collected at loop cycle `cycle`, simulated time `time_ns`.
  // `blobs` reads its blobs (valid during the call).
  virtual void from_engine(const std::string& engine, const engine::DataPack& dp,
                           const datapack::BlobReader& blobs, uint64_t cycle, int64_t time_ns) = 0;
  // A datapack that function `fn` sent to `engine` in cycle `cycle` (it goes with that
  // engine's next Step).
  virtual void to_engine(const std::string& engine, const engine::DataPack& dp,
                         const datapack::BlobReader& blobs, const LoadedFunction& fn,
                         uint64_t cycle, int64_t time_ns) = 0;
};

}  // namespace convoy::loop
