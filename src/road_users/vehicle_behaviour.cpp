// A road vehicle's step (vehicle_behaviour.h): commands first, then IDM along its path (or the
// speed command), pure pursuit on the bicycle (or the lane command), its progress along the
// route, MOBIL every 0.5 s and the route extended onward.
#include "road_users/vehicle_behaviour.h"

#include <algorithm>
#include <cmath>

#include "road_users/bicycle.h"
#include "road_users/junction.h"
#include "road_users/pure_pursuit.h"
#include "road_users/vehicle_stepper.h"

namespace convoy::road_users {
namespace odr = convoy::opendrive;
using vehicle_detail::Stepper;

namespace {

// The path it follows this step (its route's, or a commanded polyline's) and where it is on it.
struct Drive {
  const Path* path;
  size_t cursor;
  double arc;
};

}  // namespace

VehicleState start_vehicle(const VehicleDescription& d) {
  VehicleState s;
  Stepper st{d, s};
  s.driving = Driving{d.idm};
  s.path = st.make_path(d.initial_route);
  s.goals = d.initial_goals;
  s.onward = d.initial_onward;
  s.open_end = d.initial_open_end;
  s.rng = d.initial_rng;
  s.time_ns = 0;
  s.arc = d.start_s;
  const odr::Pose2 p = d.start_pose ? *d.start_pose : s.path.at(s.arc);
  s.initial_path_start = p;
  s.x = p.x;
  s.y = p.y;
  s.yaw = p.heading;
  if (d.start_pose) s.arc = s.path.project(s.x, s.y).arc;
  s.v = d.initial_speed;
  s.cursor = s.path.project(s.x, s.y).index;
  st.compute_goal_arcs();
  return s;
}

void perceive(VehicleState& s, std::shared_ptr<const Neighbours> neighbours,
              std::shared_ptr<const LightStates> lights) {
  if (neighbours) s.last_neighbours = std::move(neighbours);
  if (lights) s.last_lights = std::move(lights);
  // Stamped with the time it arrived (the state the TF saw).
  if (!s.inputs.empty() && s.inputs.back().time_ns == s.time_ns) {
    s.inputs.back().neighbours = s.last_neighbours;
    s.inputs.back().lights = s.last_lights;
  } else {
    s.inputs.push_back({s.time_ns, s.last_neighbours, s.last_lights});
  }
}

void drive_in(const VehicleDescription& d, VehicleState& s, const Weather& weather) {
  s.driving = d.weather_adaptation ? adapt_to_weather(d.idm, weather) : Driving{d.idm};
}

bool step_vehicle(const VehicleDescription& d, VehicleState& s, int64_t duration_ns) {
  return Stepper{d, s}.step(duration_ns);
}

namespace vehicle_detail {

const VehicleSnapshot* Stepper::perceived() const {
  // The newest input at least ReactionTime old.
  const int64_t limit = s.time_ns - static_cast<int64_t>(std::llround(d.reaction_s * 1e9));
  const VehicleSnapshot* best = nullptr;
  for (const auto& snap : s.inputs) {
    if (snap.time_ns <= limit) best = &snap;
  }
  return best;
}

bool Stepper::start_free() const {
  const VehicleSnapshot* snap = perceived();
  return snap && snap->neighbours &&
         road_users::start_free(*snap->neighbours, s.initial_path_start.x, s.initial_path_start.y,
                                d.length + 6.0);
}

bool Stepper::step(int64_t duration_ns) {
  const double dt = duration_ns * 1e-9;
  s.time_ns += duration_ns;
  // Drop inputs no longer needed (keep the newest one old enough).
  const int64_t limit = s.time_ns - static_cast<int64_t>(std::llround(d.reaction_s * 1e9));
  while (s.inputs.size() > 1 && s.inputs[1].time_ns <= limit) s.inputs.pop_front();
  // This step's command (it applies to this step only).
  std::optional<VehicleCommand> cmd;
  cmd.swap(s.command);
  s.commanded_acc.reset();
  const bool placed = cmd && (cmd->teleport || cmd->timed);
  if (s.absent && !placed) {
    if (!d.respawn || s.time_ns - s.absent_since_ns < std::llround(d.respawn_delay_s * 1e9) ||
        !start_free())
      return false;
    restart();
    return true;
  }
  s.absent = false;
  if (placed) return place(*cmd, dt);
  const bool on_poly = follow_commands(cmd);
  const auto [acc, v_new] = longitudinal(cmd, on_poly, dt);
  lateral(cmd, on_poly, v_new, dt);
  s.v = v_new;
  s.acc = acc;
  if (!on_poly && !s.lost) advance_on_path(dt);
  const bool ai_lateral = !s.absent && !on_poly && !s.lost && !s.lane_run.active;
  if (ai_lateral && d.lane_changes && s.changing == 0 && s.time_ns >= s.next_mobil_ns) {
    s.next_mobil_ns = s.time_ns + 500000000;  // every 0.5 s
    consider_lane_change();
  }
  if (ai_lateral && s.onward && s.goals.empty() && s.open_end && s.changing == 0 &&
      s.path.length() - s.arc < std::max(200.0, 10.0 * s.v))
    extend();
  return true;
}

void Stepper::restart() {
  s.path = make_path(d.initial_route);
  s.goals = d.initial_goals;
  s.onward = d.initial_onward;
  s.open_end = d.initial_open_end;
  s.arc = d.start_s;
  const odr::Pose2 p = d.start_pose ? *d.start_pose : s.path.at(s.arc);
  s.x = p.x;
  s.y = p.y;
  s.yaw = p.heading;
  if (d.start_pose) s.arc = s.path.project(s.x, s.y).arc;
  s.v = d.initial_speed;
  s.acc = 0;
  s.yaw_rate = 0;
  s.absent = false;
  s.changing = 0;
  s.next_mobil_ns = s.time_ns;
  s.cursor = s.path.project(s.x, s.y).index;
  compute_goal_arcs();
  s.lane_run = {};
  s.off_path = s.lost = false;
  s.commanded_acc.reset();
}

bool Stepper::place(const VehicleCommand& cmd, double dt) {
  if (cmd.teleport) {
    // Put there once, then on from the nearest lane.
    const VehicleCommand::Pose& p = *cmd.teleport;
    s.x = p.x;
    s.y = p.y;
    s.yaw = std::remainder(p.yaw, 2 * M_PI);
    if (p.speed) s.v = *p.speed;
    s.acc = s.yaw_rate = 0;
    s.lane_run = {};
    s.off_path = false;
    s.polyline.clear();
    relocalise();
    return true;
  }
  // Exactly this pose and speed (both domains).
  const VehicleCommand::Pose& p = *cmd.timed;
  const double v = p.speed.value_or(0.0);
  const double yaw = std::remainder(p.yaw, 2 * M_PI);
  s.yaw_rate = std::remainder(yaw - s.yaw, 2 * M_PI) / dt;
  s.acc = (v - s.v) / dt;
  s.x = p.x;
  s.y = p.y;
  s.yaw = yaw;
  s.v = v;
  s.lane_run = {};
  s.off_path = true;
  s.changing = 0;
  return true;
}

bool Stepper::follow_commands(const std::optional<VehicleCommand>& cmd) {
  if (cmd && cmd->route && *cmd->route != s.last_route) {
    s.last_route = *cmd->route;
    if (s.off_path && !cmd->polyline) s.off_path = false;  // re-planned from here
    apply_route(*cmd->route);
  }
  const bool on_poly = cmd && cmd->polyline;
  if (on_poly) {
    set_polyline(*cmd->polyline);
    s.off_path = true;
    s.lane_run = {};
    s.changing = 0;
  } else if (s.off_path) {
    // Back to the AI from where the command left it.
    s.off_path = false;
    s.polyline.clear();
    relocalise();
  }
  if (s.lost && !on_poly && s.time_ns >= s.next_look_ns) relocalise();
  if (cmd && cmd->lane && !s.lost) {
    begin_lane(*cmd->lane);
  } else if (s.lane_run.active) {
    s.lane_run = {};
    s.changing = 0;
  }
  return on_poly;
}

// The path it follows: its route's, or the commanded polyline's.
static Drive drive_of(const VehicleState& s, bool on_poly) {
  if (!on_poly) return {&s.path, s.cursor, s.arc};
  const auto pr = s.traj_path.project(s.x, s.y);
  return {&s.traj_path, pr.index, pr.arc};
}

// (acceleration, new speed): the speed command, else IDM along the path it follows.
std::pair<double, double> Stepper::longitudinal(const std::optional<VehicleCommand>& cmd,
                                                bool on_poly, double dt) {
  double acc = 0, v_new = s.v;
  if (cmd && cmd->speed) {
    v_new = cmd->speed->speed;
    acc = cmd->speed->acceleration ? *cmd->speed->acceleration : (v_new - s.v) / dt;
    s.commanded_acc = acc;
  } else if (s.lost) {
    acc = -std::min(s.driving.idm.b, s.v / dt);
    v_new = std::max(0.0, s.v + acc * dt);
  } else {
    const Drive drive = drive_of(s, on_poly);
    const double my_front = drive.arc + d.front_offset();
    const double v0 = desired_speed();
    const auto [gap, vl] = stop_ahead(*drive.path, drive.cursor, my_front, on_poly);
    acc = s.driving.idm.accel(s.v, gap, vl, v0);
    acc = std::clamp(acc, -d.max_decel, s.driving.idm.a);
    v_new = s.v + acc * dt;
    if (v_new < 0) {
      v_new = 0;
      acc = -s.v / dt;
    }
  }
  return {acc, v_new};
}

// The lane command, else pure pursuit on the path it follows.
void Stepper::lateral(const std::optional<VehicleCommand>& cmd, bool on_poly, double v_new,
                      double dt) {
  if (s.lane_run.active) {
    LaneRun& run = s.lane_run;
    const double p = std::clamp(run.progress, 0.0, 1.0);
    const double lat =
        (1.0 - p) * (run.d_from + run.e0) + p * (cmd->lane ? cmd->lane->offset : 0.0);
    const double ds = v_new * dt;
    const odr::Pose2 q = s.path.at(s.arc + ds);
    // Along its motion; at the end (progress 1) along the lane, as a driver straightens up.
    const double yaw = ds > 1e-6 && p < 1.0
                           ? std::remainder(q.heading + std::atan2(lat - run.lateral, ds), 2 * M_PI)
                           : q.heading;
    s.x = q.x - lat * std::sin(q.heading);
    s.y = q.y + lat * std::cos(q.heading);
    s.yaw_rate = std::remainder(yaw - s.yaw, 2 * M_PI) / dt;
    s.yaw = yaw;
    run.lateral = lat;
    s.changing = p < 1.0 ? run.side : 0;
  } else if (s.lost) {
    s.x += v_new * std::cos(s.yaw) * dt;
    s.y += v_new * std::sin(s.yaw) * dt;
    s.yaw_rate = 0;
  } else {
    const Drive drive = drive_of(s, on_poly);
    const KinematicBicycle bicycle{d.wheelbase};
    const PlanarPose pose{s.x, s.y, s.yaw};
    const double steer = pursue(PurePursuit{}, bicycle, *drive.path, drive.arc, pose, s.v, on_poly);
    const BicycleMotion moved = step_bicycle(bicycle, pose, v_new, steer, dt);
    s.x = moved.pose.x;
    s.y = moved.pose.y;
    s.yaw = moved.pose.yaw;
    s.yaw_rate = moved.yaw_rate;
  }
}

// Where it is on its path now: goals passed, and absent at the route's end.
void Stepper::advance_on_path(double dt) {
  const size_t lo = s.cursor > 20 ? s.cursor - 20 : 0;
  const auto pr = s.path.project(s.x, s.y, lo,
                                 s.cursor + 40 + static_cast<size_t>(s.v * dt / kVehicleSampleDs));
  s.cursor = pr.index;
  s.arc = pr.arc;
  if (!s.lane_run.active && s.changing != 0 && std::abs(pr.lateral) < 0.2) s.changing = 0;
  while (s.onward && !s.goals.empty() && s.arc >= s.goal_arcs.front() - 1.0) {
    s.goals.erase(s.goals.begin());
    s.goal_arcs.erase(s.goal_arcs.begin());
  }
  if (s.arc >= s.path.length() - 0.25) {
    s.absent = true;
    s.absent_since_ns = s.time_ns;
    if (d.respawn) {  // absent, it waits at its start: its view is around there
      s.x = s.initial_path_start.x;
      s.y = s.initial_path_start.y;
      s.yaw = s.initial_path_start.heading;
    }
    s.v = 0;
    s.acc = 0;
    s.yaw_rate = 0;
    s.lane_run = {};
  }
}

double Stepper::desired_speed() const {
  std::optional<double> limit;
  if (d.limit_factor > 0 && !s.path.route.segments.empty()) {
    if (const auto loc = d.graph->locate(s.x, s.y, s.yaw)) {
      const odr::SpeedLimit lim = d.graph->speed_limit(loc->lane, loc->s);
      if (lim.known) limit = lim.mps;
    }
  }
  return road_users::desired_speed(s.driving, d.limit_factor, limit);
}

// The gap to where it must stop on `drive` (cursor, front: its front bumper's arc there) and
// the speed of what it stops behind: the leader, a red light, a junction to wait at.
std::pair<double, double> Stepper::stop_ahead(const Path& drive, size_t cursor, double front,
                                              bool on_poly) const {
  const VehicleSnapshot* snap = perceived();
  if (!snap) return {INFINITY, 0};
  const Observer me = observer();
  const Idm& idm = s.driving.idm;
  LaneNeighbour leader;
  if (snap->neighbours)
    leader = leader_on(drive, cursor, front, kVehicleSampleDs, me, *snap->neighbours);
  double gap = leader.gap, vl = leader.speed;
  // Red lights: a standing virtual leader at the stop line.
  if (!on_poly && snap->lights) {
    const double g = stop_line_gap(s.path, *snap->lights, front, s.v, idm.b, d.radius);
    if (g < gap) {
      gap = std::max(g, 0.0);
      vl = 0;
    }
  }
  if (d.yielding && !on_poly && snap->neighbours) {
    const Approach at{&s.path, s.cursor, front, d.length, d.max_decel, idm};
    const double g = junction_wait(*d.graph, at, me, *snap->neighbours, snap->lights.get());
    if (g < gap) {
      gap = g;
      vl = 0;
    }
  }
  return {gap, vl};
}

}  // namespace vehicle_detail
}  // namespace convoy::road_users
