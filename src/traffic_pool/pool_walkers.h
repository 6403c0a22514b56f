// Pooled pedestrians (issue 26's city): walkers on the map's sidewalk lanes (OpenDRIVE
// type="sidewalk"), stepped with the pool's vehicles. The planning and crossing rules are
// src/road_users' (pedestrian_walks.h, walker.h); this holds many walkers in one process.
//
// A walker makes trips: from where it stands it draws (by its seed) a crosswalk whose end it can
// reach along the sidewalks (within 300 m when there is one, not the one it has just crossed),
// walks there (road_users::walk), crosses to the far sidewalk and draws the next trip there. A
// sidewalk with no crosswalk on reach: it walks on along the sidewalks (forks drawn). It walks
// at its own speed (drawn 1.2-1.5 m/s), kept 0.55 m right of its path's centre (turning over
// to it at a new trip's start), and never closer than 1 m behind a walker in its way going its
// way (within 60 degrees); it sidesteps round walkers facing it, standing or crossing its way
// and never steps to where its box overlaps another's (walker_avoid.cpp: on a crossing leg it
// keeps to its right half; from the curb to kOffRoad past the road it has the way over walkers
// on the sidewalk; blocked, it gives way to one earlier in order or standing). It steps
// onto the road only at a crosswalk, from the curb, when
//   - the lights let it: at a junction with lights, the crossed road's approach is red now and
//     will still be red when it has crossed (the pool's LightCycle); with lights given from
//     outside (step's lane_lights: states, no schedule to predict), every lit approach lane of
//     the crossed road ending within 30 m of the crosswalk is red now (not red-yellow, not
//     yellow; dark ones do not count); no lights: gap only;
//   - every vehicle (pooled or external) arrives at the line it walks its critical gap (drawn
//     3.5-5 s) or more from now (road_users::gap_accepted; a vehicle's box counted longer by
//     the walker's width + 0.6 m), and no moving vehicle comes within 8 m of the crossing;
// and while crossing it waits before, or steps back out of, a lane a vehicle is about to pass
// (road_users::crossing_limit). From the curb until it is off the road, the on-road part of its
// crossing is a box the pool's vehicles stop before (crossing_box). walk_phase: distance walked
// over its stride, mod 1.
//
// Deterministic: its draws come from its seed only (spawn_walkers: Seed, walker k Seed + k).
#pragma once

#include <algorithm>
#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "opendrive/lane_graph.h"
#include "road_users/pedestrian_walks.h"
#include "road_users/walker.h"
#include "traffic_pool/network.h"

namespace convoy::traffic_pool {

struct WalkerSpec {
  std::string id;
  opendrive::LaneIndex lane = opendrive::kNoLane;  // its start: a sidewalk lane of the graph
  double s = 0;                                    // along the road's reference line
  double speed = 1.35;                             // m/s
  double gap = 4.0;                                // s: its critical gap
  double length = 0.5, width = 0.6, height = 1.75, stride = 1.4;
  uint64_t seed = 0;
  std::string crosswalk;    // its first trip: over this crosswalk (the map's object id)
  bool obey_lights = true;  // false: it crosses on the gap alone
};

struct WalkerStats {
  uint64_t trips = 0, crossings = 0, respawns = 0;
};

// Sidewalk lanes' length, km (what a pedestrian density is per).
double sidewalk_km(const PoolNetwork& net);
// How many walkers spawn_walkers can place: slots kWalkerSpacing m apart on the sidewalks.
inline constexpr double kWalkerSpacing = 4.0;
size_t walker_capacity(const PoolNetwork& net, const std::vector<ClearZone>& keep_clear = {});
// `count` walkers (ids "<prefix><k>", seeds seed + k, speeds and gaps drawn from them) on free
// slots of the sidewalks, drawn by `seed`. Throws PoolError when they hold fewer than `count`.
std::vector<WalkerSpec> spawn_walkers(const PoolNetwork& net, size_t count, uint64_t seed,
                                      const std::string& prefix = "walker/",
                                      const std::vector<ClearZone>& keep_clear = {});

// Whether boxes a and b (centre, yaw, length along yaw, width) overlap (separating axes).
bool boxes_overlap(double ax, double ay, double ayaw, double al, double aw, double bx, double by,
                   double byaw, double bl, double bw);

// m past the road where a trip over a crosswalk ends (the next starts where it stands).
inline constexpr double kOffRoad = 0.85;

class PoolWalkers {
 public:
  // Throws PoolError naming the walker: a start off the sidewalks, an id twice, a size, speed
  // or gap that is not positive, a crosswalk the map does not have (with sidewalks at both
  // ends) or that its start cannot reach along the sidewalks.
  PoolWalkers(const PoolNetwork& net, std::vector<WalkerSpec> specs);
  // The vehicles within r m of (x, y): appended to `out`.
  using VehiclesNear =
      std::function<void(double x, double y, double r, std::vector<road_users::CrossingVehicle>&)>;
  // One step of dt s at pool time t (the lights' clock); lane_lights: each pool lane's light
  // given from outside (Pool::set_light_states), else null (the pool's own cycle).
  void step(double dt, double t, const VehiclesNear& vehicles,
            const std::vector<road_users::Light>* lane_lights = nullptr);
  size_t size() const { return w_.size(); }
  const WalkerSpec& spec(size_t i) const { return specs_[i]; }
  double x(size_t i) const { return w_[i].x; }
  double y(size_t i) const { return w_[i].y; }
  double yaw(size_t i) const { return w_[i].yaw; }
  double speed(size_t i) const { return w_[i].v; }
  double acceleration(size_t i) const { return w_[i].acc; }
  double walk_phase(size_t i) const;
  // On its crossing leg (from sidewalk centre to sidewalk centre), and off the sidewalks.
  bool crossing(size_t i) const;
  bool on_road(size_t i) const;
  // While it has stepped onto a crossing and not yet left the road: the box vehicles keep out
  // of, the part of its crossing line on the road, as wide as the walkers on it keep right.
  // While it walks a commanded polyline: its body (with a margin), wherever it is.
  struct Box {
    double x = 0, y = 0, yaw = 0, length = 0, width = 0;
  };
  bool crossing_box(size_t i, Box& box) const;
  const road_users::WalkPath& path(size_t i) const { return w_[i].path; }
  const WalkerStats& stats() const { return stats_; }
  // Pairs of walkers (i < k) whose boxes (length x width, along their yaw) overlap now.
  std::vector<std::pair<uint32_t, uint32_t>> overlaps() const;
  // Scenario commands (pool_commands.cpp): its walking speed from now on (returns the one it
  // had), and putting it at (x, y, yaw) with speed v, then on from the nearest sidewalk.
  double set_pace(size_t i, double v);
  void put_at(size_t i, double x, double y, double yaw, double v, double dt);
  // (pool_paths.cpp) A route: from where it is straight through the points, then to the nearest
  // sidewalk and on (road_users::walk_through); the same points again do not re-plan. A
  // polyline for the next step (road_users::step_along; `paced`: at a commanded speed, not
  // behind the walkers ahead); without one after it, it walks on from where it stands.
  void walk_route(size_t i, const road_users::Points& via);
  void follow_polyline(size_t i, const road_users::Points& points, bool paced);
  bool on_polyline(size_t i) const;

 private:
  struct Walker {
    road_users::WalkPath path;
    double arc = 0, v = 0, acc = 0, walked = 0, x = 0, y = 0, yaw = 0;
    double ox = 0, oy = 0;        // its offset from its path's centre (eased to kKeepRight)
    double dodge = 0;             // m further right: its sidestep round walkers in its way
    double want = 0;              // m/s: the pace it meant to walk at its last step
    size_t committed = SIZE_MAX;  // the crossing it has stepped onto
    uint64_t rng = 0;
    int last_crosswalk = -1;
  };
  struct CrosswalkInfo {
    size_t graph_index = 0;
    int junction = -1, group = -1;  // the lights of the crossed road's approach (-1: none)
    std::vector<uint32_t> lit;      // its approach lanes with signals (lights from outside)
    double x = 0, y = 0;            // its centre
  };
  void index_sidewalks();
  void plan_trip(size_t i, road_users::Spot from);
  void first_trip(size_t i);
  bool plan_crossing(size_t i, road_users::Spot from, int cw);
  void walk_on(size_t i, double x, double y, double yaw, bool may_respawn = true);
  void index_walkers();
  void step_walker(size_t i, double dt, double t, const VehiclesNear& vehicles);
  bool may_step_on(size_t i, const road_users::WalkCrossing& c, double t,
                   const VehiclesNear& vehicles);
  std::vector<road_users::CrossingThreat> threats(size_t i, const road_users::WalkCrossing& c,
                                                  const VehiclesNear& vehicles,
                                                  double* nearest_moving = nullptr) const;
  const road_users::WalkCrossing* current_crossing(size_t i) const;
  double keep_right(size_t i) const;  // m right of its path's centre (with its sidestep)
  // Its pose at `arc` with sidestep `dodge`, its offset turned by `moved` m (place: taken).
  struct Placed {
    double ox = 0, oy = 0, x = 0, y = 0, yaw = 0;
  };
  Placed placed(size_t i, double arc, double dodge, double moved) const;
  void place(size_t i, double moved);
  // walker_avoid.cpp: the pace it may keep among the walkers near it, and how far right of its
  // path it aims to be (`target`); then the step itself, only to where it overlaps no walker.
  double avoid(size_t i, double v, double& target) const;
  bool has_way(size_t i) const;
  bool gives_way_to(size_t i, uint32_t k) const;
  bool clear_at(size_t i, double x, double y, double yaw, uint32_t* who = nullptr) const;
  void move(size_t i, double v, double target, double dt);
  // pool_paths.cpp: the step of a walker with a commanded path (false: its own step).
  bool step_commanded(size_t i, double dt);
  template <class F>
  void for_near(size_t i, int reach, F&& f) const {
    const int cx = std::clamp(static_cast<int>((w_[i].x - min_x_) / 5.0), 0, gx_ - 1);
    const int cy = std::clamp(static_cast<int>((w_[i].y - min_y_) / 5.0), 0, gy_ - 1);
    for (int y = std::max(0, cy - reach); y <= std::min(gy_ - 1, cy + reach); ++y) {
      for (int x = std::max(0, cx - reach); x <= std::min(gx_ - 1, cx + reach); ++x) {
        for (uint32_t k = head_[static_cast<size_t>(y) * gx_ + x]; k != kNone; k = chain_[k]) {
          if (k != i) f(k);
        }
      }
    }
  }

  const PoolNetwork& net_;
  std::vector<WalkerSpec> specs_;
  std::vector<Walker> w_;
  std::vector<int> component_;             // per graph lane: its sidewalk network, -1 none
  std::vector<CrosswalkInfo> crosswalks_;  // with a sidewalk at both ends
  std::vector<std::vector<int>> reach_;    // per component: crosswalks an end of lies on it
  // Walkers by 5 m cell (for_near's) (rebuilt each step): cell heads and a chain.
  double min_x_ = 0, min_y_ = 0;
  int gx_ = 1, gy_ = 1;
  std::vector<uint32_t> head_, chain_;
  WalkerStats stats_;
  const std::vector<road_users::Light>* lights_ = nullptr;  // step's lane_lights
  // Commanded paths (pool_paths.cpp), by walker: its last route and polyline, the polyline's
  // walk, and whether it follows it this step (and at a commanded speed).
  struct Commanded {
    road_users::Points route, polyline;
    road_users::WalkPath walk;
    bool now = false, paced = false;
  };
  std::map<size_t, Commanded> commanded_;
};

}  // namespace convoy::traffic_pool
