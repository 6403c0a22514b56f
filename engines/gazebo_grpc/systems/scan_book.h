// What the scanning sensor systems (lidar_sensors.h, radar_sensors.h) keep alike: which sensor
// each datapack name is, the rule that a sensor scans from its first request on (that request
// scans at once), then after every engine step at which it is due, and which scan each name
// last sent (its datapack is unchanged() until the sensor scans again).
//
// `Sensor` has `bool wanted`, `uint64_t scans` and `double next_update` (s).
#pragma once

#include <algorithm>
#include <cstdint>
#include <string>
#include <unordered_map>
#include <vector>

namespace convoy::world {

template <class Sensor>
class ScanBook {
 public:
  explicit ScanBook(std::vector<Sensor>& sensors) : sensors_(sensors) {}

  void add_name(const std::string& datapack, size_t sensor) { by_datapack_[datapack] = sensor; }

  // For get_datapack(): the sensor behind `datapack` (null: none), wanted from now on; `scan`
  // runs on it if it never scanned.
  template <class Scan>
  Sensor* want(const std::string& datapack, Scan&& scan) {
    auto it = by_datapack_.find(datapack);
    if (it == by_datapack_.end()) return nullptr;
    Sensor& s = sensors_[it->second];
    if (!s.wanted) {
      s.wanted = true;
      if (s.scans == 0) scan(s);
    }
    return &s;
  }
  // The scan `datapack` now carries (after want()).
  void sent(const std::string& datapack) {
    sent_[datapack] = sensors_[by_datapack_.at(datapack)].scans;
  }
  bool unchanged(const std::string& datapack) const {
    auto it = by_datapack_.find(datapack);
    if (it == by_datapack_.end()) return false;
    auto sent = sent_.find(datapack);
    return sent != sent_.end() && sent->second == sensors_[it->second].scans;
  }

  // For after_step(): `scan` on every wanted sensor due at `t`, from half a physics step early
  // as the cameras (clocks in whole nanoseconds).
  template <class Scan>
  void scan_due(double t, double half_step, Scan&& scan) {
    for (auto& s : sensors_)
      if (s.wanted && (s.scans == 0 || t + half_step >= s.next_update)) scan(s);
  }
  // After a scan at `t`: counted, and due again a `period` later (0: every step), on its own
  // schedule unless it fell behind.
  static void scanned(Sensor& s, double t, double period) {
    ++s.scans;
    s.next_update = period > 0 ? std::max(s.next_update + period, t) : t;
    if (period > 0 && s.next_update <= t) s.next_update = t + period;
  }
  // For reset(): nothing sent, every sensor unwanted, unscanned and due at once.
  void reset() {
    sent_.clear();
    for (auto& s : sensors_) {
      s.next_update = 0;
      s.wanted = false;
      s.scans = 0;
    }
  }

 private:
  std::vector<Sensor>& sensors_;
  std::unordered_map<std::string, size_t> by_datapack_;
  std::unordered_map<std::string, uint64_t> sent_;  // datapack -> the scan sent
};

}  // namespace convoy::world
