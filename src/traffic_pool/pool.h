// N vehicles in one process (issue 26's pooled host), each with its own parameters, seed and
// policy: IDM car following (road_users::Idm), MOBIL lane changes (road_users::Mobil), yielding
// at junctions (a vehicle claims its junction lane before entering; it waits while a crossing
// or merging lane is claimed or occupied, and while its exit lane has no room) and the pool's
// traffic lights (PoolNetwork). State is kept in arrays, one entry per vehicle; neighbours off
// the lane (vehicles in junctions, and the collision check) are found in a uniform grid.
//
// External road users (the ego, agent engines' road users: set_external) are obstacles the
// pool never moves: each sits in the grid and on every lane its box reaches (pool_external.cpp),
// so pooled vehicles follow it (IDM leader), keep MOBIL's gaps to it, wait while it occupies a
// junction lane crossing theirs, and are not respawned onto it.
//
// Lights: the pool's own cycle (PoolNetwork::light(lane, t)) until set_light_states gives the
// signals' states from outside (the traffic_lights engine's); from then on an approach's light
// is the stricter of its own signals' and those of the junction lane it turns onto
// (PoolNetwork::signal_light), for the vehicles and the walkers.
//
// Walkers (set_walkers, pool_walkers.h) step with the vehicles, after them (seeing the vehicles
// and externals where they are then). The crossing a walker has stepped onto is an obstacle to
// the vehicles like an external road user (PoolWalkers::crossing_box: the on-road part of its
// line, in the grid and on every lane it reaches), so vehicles stop before the crosswalk while
// it is on it, and are not respawned onto it.
//
// Bad input throws PoolError naming the road user: an unknown policy, a start off the driving
// lanes, two road users on one spot, a destination with no path, a count that does not fit.
#pragma once

#include <algorithm>
#include <cstdint>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "road_users/command.h"
#include "road_users/idm.h"
#include "road_users/lights.h"
#include "road_users/mobil.h"
#include "road_users/pedestrian_command.h"
#include "traffic_pool/network.h"
#include "traffic_pool/pool_walkers.h"

namespace convoy::traffic_pool {

class PoolError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Policies: "idm_mobil" (car following, lane changes, junctions, lights) and "idm" (the same
// without lane changes).
inline constexpr const char* kPolicies[] = {"idm_mobil", "idm"};

struct VehicleSpec {
  std::string id;
  std::string policy = "idm_mobil";
  std::string road;  // start: road, lane, s along the lane's driving direction (its front)
  int lane = 0;
  double s = 10, speed = 0;
  std::optional<std::pair<std::string, int>> to;  // destination road and lane (then onward)
  road_users::Idm idm;
  road_users::Mobil mobil;
  double length = 4.5, width = 1.8;
  uint64_t seed = 0;           // its choices at forks
  uint32_t pool_lane = kNone;  // spawned: the PoolNetwork lane itself (road/lane/s are shown)
  bool absent = false;         // waits outside the network until Pool::enter (a flow's vehicle)
};

// `count` vehicles like `base` (ids "<prefix><k>", seeds seed + k) on free slots of the
// network's driving lanes outside junctions, spaced at least base.length + base.idm.s0 + 2 m,
// none with its centre in a `keep_clear` zone, drawn by `seed`. Throws PoolError when the
// network has fewer slots than `count`.
std::vector<VehicleSpec> spawn(const PoolNetwork& net, size_t count, uint64_t seed,
                               const VehicleSpec& base, const std::string& prefix = "pool/",
                               const std::vector<ClearZone>& keep_clear = {});
// How many vehicles like `base` spawn() can place (its slots).
size_t spawn_capacity(const PoolNetwork& net, const VehicleSpec& base,
                      const std::vector<ClearZone>& keep_clear = {});
// Length of the driving lanes outside junctions, km (what a density is per).
double driving_km(const PoolNetwork& net);

// A road user the pool does not drive: the centre of its box, heading, speed and size.
struct ExternalUser {
  std::string id;
  double x = 0, y = 0, yaw = 0, speed = 0, length = 4.5, width = 1.8;
};

struct PoolStats {
  uint64_t lane_changes = 0, junction_entries = 0, respawns = 0;
};

class Pool {
 public:
  Pool(const PoolNetwork& net, std::vector<VehicleSpec> specs, double cell_m = 20);
  void step(double dt);  // s
  // The external road users as of now, replacing the last ones; kept until the next call.
  void set_external(std::vector<ExternalUser> users);
  const std::vector<ExternalUser>& external() const { return ext_; }
  size_t size() const { return n_; }  // pooled vehicles (indices 0..size()-1)
  double time() const { return t_; }
  const VehicleSpec& spec(size_t i) const { return specs_[i]; }
  // The centre of its box, its heading, speed and acceleration.
  double x(size_t i) const { return x_[i]; }
  double y(size_t i) const { return y_[i]; }
  double yaw(size_t i) const { return yaw_[i]; }
  double speed(size_t i) const { return v_[i]; }
  double acceleration(size_t i) const { return acc_[i]; }
  uint32_t lane(size_t i) const { return lane_[i]; }
  double s(size_t i) const { return s_[i]; }
  const PoolStats& stats() const { return stats_; }
  // Flows (a demand given from outside): a vehicle at a dead end leaves the network and stays
  // absent, instead of starting again at an entry.
  void set_leave_at_exits(bool on) { leave_at_exits_ = on; }
  bool present(size_t i) const { return lane_[i] != kNone; }
  // Put off the lanes by a command (pool_commands.cpp): not present, standing at x, y.
  bool standing(size_t i) const { return !stand_.empty() && stand_[i]; }
  // Puts absent vehicle i, standing, at the start of pool lane `lane` (outside junctions), on
  // the route to its spec's `to` when it has one. False, changing nothing, while that start is
  // not free (as for a respawn) or another vehicle entered the lane this step. Throws PoolError
  // when it is present, the lane is in a junction, or its `to` has no path from there.
  bool enter(size_t i, uint32_t lane);
  // Pairs of vehicles whose boxes overlap now (found through the grid).
  std::vector<std::pair<uint32_t, uint32_t>> overlaps() const;
  // Pairs (pooled vehicle, external road user) whose boxes overlap now.
  std::vector<std::pair<uint32_t, uint32_t>> external_overlaps() const;
  // The signals' states (OpenDRIVE id -> light; one not in them is green), replacing the pool's
  // own cycle from now on; kept until the next call.
  void set_light_states(const road_users::LightStates& states);
  bool external_lights() const { return !lane_light_.empty(); }
  // The light at approach lane `lane`'s stop line for one going on to junction lane `next`.
  road_users::Light light(uint32_t lane, uint32_t next) const;
  // Walkers to step with the vehicles, replacing any (placed now). Throws PoolError as
  // PoolWalkers does, and when a walker has a vehicle's id.
  void set_walkers(std::vector<WalkerSpec> specs);
  const PoolWalkers* walkers() const { return walkers_ ? &*walkers_ : nullptr; }
  // Pairs (pooled vehicle, walker) whose boxes overlap now.
  std::vector<std::pair<uint32_t, uint32_t>> walker_overlaps() const;
  // Scenario commands for the next step (pool_commands.cpp; docs/road_users.md, "Pooled road
  // users"): `pack` is {"<id>": command, ...}, ids with or without `prefix`, each command read
  // by road_users' parser (the agents' contract). A pose's point lies `ref_ahead` x length
  // behind the box's centre (the published reference point). Throws PoolError naming `where`
  // and the road user: an unknown id, a bad command.
  void set_commands(const nlohmann::json& pack, const std::string& where, const std::string& prefix,
                    double ref_ahead);

 private:
  void validate();
  void place(size_t i);
  void index_lanes();
  void build_grid();
  double accel_of(size_t i);
  double leader_gap(size_t i, double& vl) const;
  double junction_gap(size_t i);
  double grid_gap(size_t i, double& vl) const;
  bool conflict_free(uint32_t junction_lane, size_t me) const;
  bool external_arriving(uint32_t junction_lane) const;
  bool exit_has_room(uint32_t exit_lane, double need) const;
  void consider_lane_change(size_t i);
  void advance(size_t i, double dt);
  uint32_t choose(size_t i, uint32_t lane);
  void respawn(size_t i);
  bool start_free(size_t i, uint32_t lane, double s) const;
  void start_at(size_t i, uint32_t lane, double s);
  void plan_route(size_t i, uint32_t lane, double s);
  void update_pose(size_t i);
  void place_externals();
  void step_walkers(double dt);
  void index_lane_points();
  void add_lane_entries(uint32_t e);
  void add_lane_entry(uint32_t e, uint32_t lane, double s_centre, double half_along, double v);
  template <class F>
  void for_near(double x, double y, double r, F&& f) const;
  // pool_commands.cpp
  void command_before_move(double dt);
  void command_after_move(double dt);
  void command_walkers_after(double dt);
  void put_at(size_t i, const road_users::CommandPose& p);
  void command_lane(size_t i, const road_users::VehicleCommand::Lane& want);
  void command_route(size_t i, const road_users::Points& positions);
  bool commanded_lateral(size_t i) const;
  // pool_paths.cpp: an untimed trajectory (polyline) driven this step, and the walkers' paths.
  bool on_polyline(size_t i) const;
  void drive_polyline(size_t i, const road_users::VehicleCommand& c, double dt);
  double polyline_accel(size_t i, const road_users::Path& path, double v0);
  void command_walker_paths();

  const PoolNetwork& net_;
  // Entries: 0..n_-1 pooled vehicles, then one grid entry per external road user (lane kNone),
  // then one lane entry per lane an external's box reaches (on the lanes, not in the grid).
  size_t n_ = 0, grid_end_ = 0;
  std::vector<VehicleSpec> specs_;
  std::vector<ExternalUser> ext_;
  std::vector<ExternalUser> obs_;  // the externals, then the walkers on crossing legs
  std::vector<uint32_t> ext_of_;   // entry - n_ -> its obstacle (obs_)
  std::optional<PoolWalkers> walkers_;
  // Lane sample points by 10 m cell (built on the first external): lane << 32 | pose index.
  std::vector<uint32_t> point_begin_;
  std::vector<uint64_t> points_;
  int px_ = 0, py_ = 0;
  double t_ = 0;
  // Per vehicle.
  std::vector<uint32_t> lane_, prev_, next_, next2_, claim_;
  std::vector<double> s_, v_, acc_, x_, y_, yaw_;
  std::vector<uint64_t> rng_;
  std::vector<std::vector<uint32_t>> route_;  // lanes still to drive (destination given)
  std::vector<uint8_t> mobil_;
  std::vector<uint32_t> entries_;  // lanes no lane leads into (the map's edges): respawns
  // Per lane: vehicles on it by s (rebuilt each step), claims of junction lanes, changes in.
  std::vector<uint32_t> order_, lane_begin_, rank_;
  std::vector<uint16_t> claims_;
  std::vector<uint8_t> changed_into_;
  // The grid: cell heads and a chain through the vehicles.
  double cell_ = 20;
  int gx_ = 1, gy_ = 1;
  std::vector<uint32_t> cell_head_, cell_next_;
  PoolStats stats_;
  bool leave_at_exits_ = false;
  std::vector<road_users::Light> lane_light_;   // per lane, from set_light_states (empty: own)
  std::vector<std::vector<uint32_t>> feeders_;  // junction lane -> the approaches into it
  // Commands (pool_commands.cpp): this step's per vehicle and walker, the last route command's
  // positions, vehicles standing off the lanes (put 50 m from them: lane kNone).
  bool has_commands_ = false;
  double cmd_ref_ahead_ = 0;
  std::map<std::string, size_t> index_;  // id -> vehicle, or n_ + walker
  std::vector<std::optional<road_users::VehicleCommand>> cmd_;
  std::vector<std::optional<road_users::PedestrianCommand>> wcmd_;
  std::vector<road_users::Points> routed_;
  std::vector<road_users::Points> polyline_;  // the last polyline driven, and its path
  std::vector<road_users::Path> poly_path_;
  std::vector<uint8_t> stand_;
  std::vector<std::pair<size_t, double>> pace_;  // walkers on a commanded pace: their own
};

template <class F>
inline void Pool::for_near(double x, double y, double r, F&& f) const {
  const int x0 = std::max(0, static_cast<int>((x - r - net_.min_x + 20) / cell_));
  const int x1 = std::min(gx_ - 1, static_cast<int>((x + r - net_.min_x + 20) / cell_));
  const int y0 = std::max(0, static_cast<int>((y - r - net_.min_y + 20) / cell_));
  const int y1 = std::min(gy_ - 1, static_cast<int>((y + r - net_.min_y + 20) / cell_));
  for (int cy = y0; cy <= y1; ++cy) {
    for (int cx = x0; cx <= x1; ++cx) {
      for (uint32_t k = cell_head_[static_cast<size_t>(cy) * gx_ + cx]; k != kNone;
           k = cell_next_[k]) {
        f(k);
      }
    }
  }
}

}  // namespace convoy::traffic_pool
