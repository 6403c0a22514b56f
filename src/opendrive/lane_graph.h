// The lane graph of an OpenDRIVE network: every lane of every lane section as a node, joined
// across lane sections, across roads (road links, contact points, lane links) and through
// junctions (connections and their lane links); lane-change adjacency; shortest routes from
// lane to lane; (s, t) <-> world; speed limits, crosswalks, sidewalks and signals.
//
// Directions: a lane is driven with the road's s (forward) when its id is negative under
// right-hand traffic (RHT, the default) or positive under LHT, against s otherwise.
// Connectivity is stored direction-neutral, between lane ends (a lane's start is at its
// section's s, its end at the section's end); routes follow it in the driving direction (or in
// both directions for pedestrians on sidewalks).
//
// Where a lane <link> is missing, a lane continues into the lane with the same id, as common
// tools do. Building throws std::runtime_error naming the file and the road / junction /
// connection for links the graph cannot follow (a connection naming a missing road, a road
// linking to a missing junction).
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <set>
#include <string>
#include <unordered_map>
#include <vector>

#include "opendrive/network.h"

namespace convoy::opendrive {

using LaneIndex = uint32_t;
inline constexpr LaneIndex kNoLane = UINT32_MAX;

enum class LaneEnd : uint8_t { kStart, kEnd };  // of the lane section, in road s

struct LaneEndRef {
  LaneIndex lane = kNoLane;
  LaneEnd end = LaneEnd::kStart;
  auto operator<=>(const LaneEndRef&) const = default;
};

struct LaneNode {
  LaneIndex index = kNoLane;
  const Road* road = nullptr;
  size_t road_index = 0;  // into Network::roads
  size_t section = 0;     // into Road::sections
  int lane_id = 0;
  std::string type;                          // driving, sidewalk, ...
  double s0 = 0, s1 = 0;                     // the section's s range
  double length = 0;                         // along the lane centre (m)
  bool forward = true;                       // driven with s
  std::string junction;                      // the road's junction id, "-1" outside junctions
  std::vector<LaneEndRef> at_start, at_end;  // lane ends joined to this lane's start / end
  // Neighbours in the same section on the same side of the centre (lane ids +-1), and
  // whether the road mark between allows a change (not solid / solid solid / ...).
  LaneIndex inner = kNoLane, outer = kNoLane;
  bool change_to_inner = false, change_to_outer = false;
  // To the left / right of the driving direction (inner or outer by side and direction).
  LaneIndex left() const;
  LaneIndex right() const;
  bool change_left() const;
  bool change_right() const;
  bool drivable() const { return type == "driving"; }
};

// A position on a lane. t is lateral from the lane centre, positive to the left of the
// road's reference direction (not of the driving direction); road_t is the same offset from
// the road's reference line (what convoy.data.RoadUser's `t` holds).
struct LanePosition {
  LaneIndex lane = kNoLane;
  std::string road_id;
  int lane_id = 0;
  double s = 0;
  double t = 0;
  double road_t = 0;
  double heading = 0;   // of the lane's driving direction, at s (rad)
  double distance = 0;  // from the lane's borders (0 inside the lane)
};

struct WorldPose {
  double x = 0, y = 0, z = 0;
  double heading = 0;  // in the lane's driving direction
};

struct RouteOptions {
  std::set<std::string> lane_types{"driving"};  // lanes a route may use
  bool both_directions = false;                 // pedestrians: any lane either way
  bool lane_changes = true;
  bool respect_road_marks = true;  // no change across a solid line
  double lane_change_cost = 10.0;  // m added per change (prefers fewer changes)
};

// One piece of a route: a lane from s_from to s_to (s_from > s_to when against s).
struct RouteSegment {
  LaneIndex lane = kNoLane;
  std::string road_id;
  int lane_id = 0;
  std::string junction;  // "-1" outside junctions
  double s_from = 0, s_to = 0;
  bool lane_change = false;  // entered from the previous segment by a lane change
  int change_direction = 0;  // +1 left, -1 right of the driving direction (lane_change only)
};

struct LaneRoute {
  std::vector<RouteSegment> segments;
  double length = 0;                   // along lane centres (m), without lane_change_cost
  double cost = 0;                     // what the search minimised
  std::vector<std::string> junctions;  // crossed, in order
  int lane_changes = 0;
};

struct SpeedLimit {
  double mps = 0;  // +inf = no limit
  bool known = false;
};

struct Crosswalk {
  std::string road_id;
  std::string id;
  double s = 0, t = 0;
  std::vector<std::array<double, 2>> polygon;  // world x, y (the outline, or the object's box)
  std::vector<LaneIndex> lanes;                // lanes of the section at s it covers
  // The sidewalks it leads to: the nearest sidewalk lane within 3 m beyond each end of its
  // t range (ends[0] on the -t side, ends[1] on the +t side), kNoLane where there is none.
  std::array<LaneIndex, 2> ends{kNoLane, kNoLane};
};

struct SignalInfo {
  const Signal* signal = nullptr;
  std::string road_id;
  WorldPose pose;                        // on the road at (s, t), heading of the road at s
  bool traffic_light = false;            // dynamic, type 1000001
  bool pedestrian_light = false;         // dynamic, type 1000002
  std::vector<LaneIndex> lanes;          // lanes of the section at s it applies to
  std::vector<std::string> controllers;  // ids of controllers that switch it
  std::string junction;                  // of the first of them named by a junction, else empty
};

class LaneGraph {
 public:
  // Builds the graph; `network` must outlive it.
  explicit LaneGraph(const Network& network);

  const Network& network() const { return *net_; }
  const std::vector<LaneNode>& lanes() const { return lanes_; }
  const LaneNode& lane(LaneIndex i) const { return lanes_.at(i); }
  // The lane with this id in the section of `road` containing s (the first section for
  // s < 0, the last for s > length). kNoLane if there is none.
  LaneIndex find(const std::string& road_id, int lane_id, double s) const;
  // The same, throwing a message naming the file, road and lane (and the lanes there are).
  LaneIndex require(const std::string& road_id, int lane_id, double s) const;
  // A lane's first section in its travel direction (entry) or last (exit).
  LaneIndex entry_lane(const std::string& road_id, int lane_id) const;
  LaneIndex exit_lane(const std::string& road_id, int lane_id) const;

  // Lanes that follow / precede one in its driving direction.
  std::vector<LaneIndex> successors(LaneIndex lane) const;
  std::vector<LaneIndex> predecessors(LaneIndex lane) const;

  // Shortest route (cost = length along lane centres + lane_change_cost per change) from a
  // position on one lane to one on another, s in road coordinates; ties are broken by lane
  // index, so the result is deterministic. nullopt when there is none.
  std::optional<LaneRoute> route(LaneIndex from, double s_from, LaneIndex to, double s_to,
                                 const RouteOptions& options = {}) const;
  // From the entry of road:lane to the exit of road:lane.
  std::optional<LaneRoute> route(const std::string& from_road, int from_lane,
                                 const std::string& to_road, int to_lane,
                                 const RouteOptions& options = {}) const;
  // Poses along a route's lane centres, ds apart (the last one at the route's end), heading in
  // the direction of travel; lane changes blend across over at most 30 m.
  std::vector<Pose2> sample(const LaneRoute& route, double ds) const;

  // World pose of (road, lane, s, t); t lateral from the lane centre, positive left of the
  // reference direction. Throws for an unknown road or lane.
  WorldPose world_pose(const std::string& road_id, int lane_id, double s, double t = 0) const;
  // The lane at a world point: the nearest lane (inside one if any); with a heading, among
  // lanes the point is inside, the one whose driving direction is closest to it.
  // nullopt when no road is within max_distance of the point.
  std::optional<LanePosition> locate(double x, double y, std::optional<double> heading = {},
                                     double max_distance = 5.0) const;
  // The same among the lanes `accept` takes (given the lane and its driving direction's
  // heading there, rad); the others are not considered at all.
  using LaneFilter = std::function<bool(const LaneNode& lane, double lane_heading)>;
  std::optional<LanePosition> locate_if(double x, double y, std::optional<double> heading,
                                        double max_distance, const LaneFilter& accept) const;

  SpeedLimit speed_limit(LaneIndex lane, double s) const;
  const std::vector<Crosswalk>& crosswalks() const { return crosswalks_; }
  std::vector<LaneIndex> sidewalks() const;
  const std::vector<SignalInfo>& signals() const { return signals_; }
  // Non-fatal findings (lane links naming lanes that do not exist), "file: junction 4 ...".
  const std::vector<std::string>& warnings() const { return warnings_; }
  // Signals named by a junction's controllers.
  std::vector<const SignalInfo*> junction_signals(const std::string& junction_id) const;

 private:
  struct RoadIndex {
    std::vector<std::vector<LaneIndex>> section_lanes;  // [section][lane id - min id]
    std::vector<int> section_min_id;
    std::vector<double> stations;  // s of the reference polyline
    std::vector<std::array<double, 2>> points;
    double min_x = 0, min_y = 0, max_x = 0, max_y = 0;  // with the lanes' widths
  };
  void add_lanes();
  void link_sections();
  void link_roads();
  void link_junctions();
  void join(LaneEndRef a, LaneEndRef b);
  void index_geometry();
  void collect_objects();
  LaneIndex lane_in_section(size_t road, size_t section, int lane_id) const;
  [[noreturn]] void fail(const std::string& what) const;

  const Network* net_;
  std::vector<LaneNode> lanes_;
  std::vector<RoadIndex> roads_;
  std::unordered_map<std::string, size_t> road_by_id_;
  std::vector<Crosswalk> crosswalks_;
  std::vector<SignalInfo> signals_;
  std::vector<std::string> warnings_;
};

}  // namespace convoy::opendrive
