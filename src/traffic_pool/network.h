// The pool's view of a lane graph: every driving lane as a polyline with its successors, its
// same-direction neighbours, its speed limit, the junction it is in or leads into, the light
// group of its approach and, for lanes inside a junction, the junction lanes it crosses or
// merges with. Built once from an opendrive::LaneGraph (any OpenDRIVE map), then read-only.
//
// Stop lines: an approach lane's vehicles wait at its end, or before a crosswalk that crosses it
// within 15 m of its end (stop_back).
//
// Lights: a junction has lights when the map gives it signals (LaneGraph::junction_signals).
// The pool runs them itself on a fixed cycle: approaches heading mostly east-west (group 0) and
// mostly north-south (group 1) take turns: green, yellow, all red (LightCycle).
//
// Lights given from outside (the traffic_lights engine's states, road_users::LightStates): a
// lane's light is that of the traffic lights (type 1000001) the map puts on it, as
// road_users::red_for finds them (SignalInfo::lanes). An approach lane takes those within
// kSignalReach m of its end, on it or on the lanes before it on its road; a junction lane those
// on it (a turn's own light). PoolLane::signals lists them.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "opendrive/geometry.h"
#include "opendrive/lane_graph.h"
#include "road_users/lights.h"

namespace convoy::traffic_pool {

inline constexpr uint32_t kNone = UINT32_MAX;
inline constexpr double kSignalReach = 50;  // m from an approach's end to its lights

struct PoolLane {
  opendrive::LaneIndex graph_lane = opendrive::kNoLane;
  std::string road_id;
  int lane_id = 0;
  std::vector<opendrive::Pose2> poses;  // along the driving direction, ds apart (last: the end)
  double ds = 1.0, length = 0;
  double limit = 13.9;                   // m/s (the map's, else 50 km/h)
  std::vector<uint32_t> next;            // pool lanes that follow
  uint32_t left = kNone, right = kNone;  // same-direction neighbours a change may go to
  int junction = -1;                     // the junction the lane is inside
  int approach = -1;                    // the junction the lane leads into (its end is a stop line)
  int group = -1;                       // light group of that approach (-1: no lights)
  double stop_back = 0;                 // m before its end where it stops (before a crosswalk)
  std::vector<uint32_t> conflicts;      // junction lanes: those it crosses or merges with
  bool u_turn = false;                  // turns back (heading change > 150 degrees)
  std::vector<std::string> signals;     // traffic lights (OpenDRIVE ids) of its stop line
  opendrive::Pose2 at(double s) const;  // s from the lane's start in its driving direction
};

// A disc kept clear of spawned road users (another road user's start, e.g. the ego's).
struct ClearZone {
  double x = 0, y = 0, radius = 0;
};

struct PoolJunction {
  std::string id;
  bool lights = false;
  double offset_s = 0;  // of its light cycle
};

struct LightCycle {
  double green_s = 25, yellow_s = 3, all_red_s = 2;
  double period() const { return 2 * (green_s + yellow_s + all_red_s); }
  road_users::Light state(double t, double offset_s, int group) const;
};

// The more restrictive of two lights (red, red-yellow, yellow, green, off).
road_users::Light stricter(road_users::Light a, road_users::Light b);

class PoolNetwork {
 public:
  explicit PoolNetwork(const opendrive::LaneGraph& graph, double ds = 1.0);
  const opendrive::LaneGraph& graph() const { return *graph_; }
  const std::vector<PoolLane>& lanes() const { return lanes_; }
  const PoolLane& lane(uint32_t i) const { return lanes_[i]; }
  const std::vector<PoolJunction>& junctions() const { return junctions_; }
  uint32_t pool_lane(opendrive::LaneIndex graph_lane) const;  // kNone: not a driving lane
  const LightCycle& cycle() const { return cycle_; }
  road_users::Light light(uint32_t approach_lane, double t) const;
  // The light of a lane from the signals' states: the most restrictive of its signals' (red or
  // red-yellow, then yellow, then green; a signal not in `states` is green); kOff when it has
  // none, or all of them are off.
  road_users::Light signal_light(uint32_t lane, const road_users::LightStates& states) const;
  double min_x = 0, min_y = 0, max_x = 0, max_y = 0;  // bounding box of the lanes

 private:
  void add_lanes(double ds);
  void link();
  void find_conflicts();
  void find_stop_lines();
  void find_signals();
  const opendrive::LaneGraph* graph_;
  std::vector<PoolLane> lanes_;
  std::vector<uint32_t> by_graph_lane_;
  std::vector<PoolJunction> junctions_;
  LightCycle cycle_;
};

}  // namespace convoy::traffic_pool
