// Several DataPackTaps as one: the recorder and the live server see the same datapacks, in
// the order they were added.
#pragma once

#include <vector>

#include "loop/datapack_tap.h"

namespace convoy::loop {

class TapFanout final : public DataPackTap {
 public:
  void add(DataPackTap* tap) {
    if (tap) taps_.push_back(tap);
  }
  bool empty() const { return taps_.empty(); }
  // The one tap, when there is one (no fan-out needed); else this.
  DataPackTap* single_or_this() { return taps_.size() == 1 ? taps_[0] : this; }

  void from_engine(const std::string& engine, const engine::DataPack& dp,
                   const datapack::BlobReader& blobs, uint64_t cycle, int64_t time_ns) override {
    for (auto* t : taps_) t->from_engine(engine, dp, blobs, cycle, time_ns);
  }
  void to_engine(const std::string& engine, const engine::DataPack& dp,
                 const datapack::BlobReader& blobs, const LoadedFunction& fn, uint64_t cycle,
                 int64_t time_ns) override {
    for (auto* t : taps_) t->to_engine(engine, dp, blobs, fn, cycle, time_ns);
  }

 private:
  std::vector<DataPackTap*> taps_;
};

}  // namespace convoy::loop
