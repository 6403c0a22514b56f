"""What convoy_gym's scenario environments share (scenario_env.py, multi_agent_env.py): one
NRPCoreSim server running a scenario episode config (scenario_config.py), the learning road
users' actions turned into their agents' commands (docs/road_users.md, Commands), their
observations, and their rewards from the live metrics (convoy_bench.live.LiveScore).

Everything here is a function of the states the status function returns, in order: the same
seed and actions give the same episode, bit for bit.

Timing: the status function runs at the start of a cycle, on the engines' datapacks of the
step before, so the states a run_loop(1) returns are those at the start of the step it ran:
one step (0.05 s) behind the command sent with it. Commands are obeyed exactly, so a learner
integrates its actions from the state its own last command gave (`pred`), not from the
observed state; a reset runs the teleport step and one neutral step, so that the first
observation shows the start."""
import math
import shutil
import socket
import tempfile

import numpy as np

from convoy_bench import geometry, score
from convoy_bench.live import LiveScore
from convoy_gym import spaces
from convoy_gym.scenario_config import build_episode_config
from convoy_scenario.player import box_collisions
from nrp_client import NrpCore

DT = 0.05                  # s, the scenario engine's and the agents' step
N_USERS = 8                # road users in the observation, nearest first
USER_COLUMNS = ("present", "forward", "left", "yaw", "speed", "length", "width", "pedestrian")
ROUTE_AHEAD = (5.0, 10.0, 20.0, 40.0, 80.0)   # m along the route past the agent's progress
EGO_KEYS = ("x", "y", "yaw", "speed", "acceleration", "yaw_rate", "route_offset")
OBSERVATIONS = ("ego", "road_users", "route")
# actions: vehicles
MAX_ACCEL, MAX_BRAKE = 3.0, 8.0    # m/s^2 at throttle 1, brake 1
MAX_STEER = 0.6                    # rad
MAX_SPEED = 20.0                   # m/s
LANE_CHANGE_S = 3.0                # s for a lane change of the target_speed_lane action
LANE_WIDTH = 3.5                   # m: where the next lane's centre is looked for
# actions: pedestrians
MAX_WALK = 3.0                     # m/s
MAX_TURN = 1.5                     # rad/s
ACTIONS = {
    ("vehicle", "controls"): (("throttle", "brake", "steer"), [0.0, 0.0, -MAX_STEER], [1.0, 1.0, MAX_STEER]),
    ("vehicle", "target_speed_lane"): (("target_speed", "lane_change"), [0.0, -1.0], [MAX_SPEED, 1.0]),
    ("pedestrian", "controls"): (("speed", "turn_rate"), [0.0, -MAX_TURN], [MAX_WALK, MAX_TURN]),
    ("pedestrian", "target_speed_lane"): (("target_speed",), [0.0], [MAX_WALK]),
}
# rewards (default_reward)
INFRACTION_WEIGHT = 50.0     # reward -50 x (1 - the CARLA penalty factor) per infraction
COMFORT_WEIGHT = 0.1         # per (m/s^2, rad/s) above nuPlan's comfort bounds, per s
LON_ACCEL = (-4.05, 2.40)    # nuPlan's comfort bounds (docs/scoring.md)
LAT_ACCEL = 4.89
YAW_RATE = 0.95


def free_address():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return "127.0.0.1:%d" % s.getsockname()[1]


def action_space(kind, action):
    if (kind, action) not in ACTIONS:
        raise ValueError("action must be 'controls' or 'target_speed_lane', got %r" % (action,))
    names, low, high = ACTIONS[(kind, action)]
    return names, spaces.Box(low=np.array(low), high=np.array(high), dtype=np.float32)


def check_action(action, space, names, who=""):
    """The action as float64, or ValueError naming the element, its value and the bound."""
    try:
        a = np.asarray(action, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError("%saction %r is not an array of %d numbers [%s]"
                         % (who, action, len(names), ", ".join(names))) from None
    if a.shape != space.shape:
        raise ValueError("%saction %r has shape %s, the action space %s [%s]"
                         % (who, action, a.shape, space.shape, ", ".join(names)))
    for i, name in enumerate(names):
        low, high = float(space.low[i]), float(space.high[i])
        if not np.isfinite(a[i]):
            raise ValueError("%saction[%d] (%s) = %r is not a finite number" % (who, i, name, a[i]))
        if a[i] < low:
            raise ValueError("%saction[%d] (%s) = %r is below the action space's bound %g"
                             % (who, i, name, a[i], low))
        if a[i] > high:
            raise ValueError("%saction[%d] (%s) = %r is above the action space's bound %g"
                             % (who, i, name, a[i], high))
    return a


def observation_space(observation):
    parts = tuple(observation)
    bad = [p for p in parts if p not in OBSERVATIONS]
    if "camera" in parts:
        raise ValueError("observation 'camera': scenario episodes run without the world engine "
                         "(kinematic road users), so there is no camera yet; choose from %s"
                         % (OBSERVATIONS,))
    if bad or not parts:
        raise ValueError("observation: unknown part(s) %s; choose from %s" % (bad, OBSERVATIONS))
    inf = np.inf
    space = {
        "ego": spaces.Box(low=np.array([-inf, -inf, -np.pi, 0.0, -inf, -inf, 0.0]),
                          high=np.array([inf, inf, np.pi, inf, inf, inf, inf]), dtype=np.float32),
        "road_users": spaces.Box(-inf, inf, (N_USERS, len(USER_COLUMNS)), dtype=np.float32),
        "route": spaces.Box(-inf, inf, (len(ROUTE_AHEAD), 2), dtype=np.float32),
    }
    return spaces.Dict({p: space[p] for p in parts})


def default_reward(before, after, action):
    """The default reward of a learning road user's step, from its live metrics (`after`, a
    dict; `before` the previous step's): the route progress gained this step (m, counted as
    CARLA's route completion counts it: none off the road or the wrong way), minus
    INFRACTION_WEIGHT x (1 - CARLA's penalty factor) per new infraction (a collision with a
    pedestrian -25, a vehicle -20, an object -17.5, a red light -15), minus COMFORT_WEIGHT per
    m/s^2 (rad/s) above nuPlan's comfort bounds per second (longitudinal acceleration
    (-4.05, 2.40), lateral 4.89, yaw rate 0.95)."""
    r = after["progress"] - before["progress"]
    r -= INFRACTION_WEIGHT * sum(1.0 - i["penalty"] for i in after["new_infractions"])
    r -= COMFORT_WEIGHT * after["discomfort"] * DT
    return float(r)


def discomfort(u):
    a, w = float(u.get("acceleration") or 0.0), float(u.get("yaw_rate") or 0.0)
    lat = float(u.get("speed") or 0.0) * w
    return (max(0.0, LON_ACCEL[0] - a) + max(0.0, a - LON_ACCEL[1]) + max(0.0, abs(lat) - LAT_ACCEL)
            + max(0.0, abs(w) - YAW_RATE))


class Learner:
    """One learning road user: its action -> its agent's command, its metrics per step."""

    def __init__(self, entity, spec, action, route, map_path, road_map, stop_lines=()):
        self.entity, self.engine, self.kind = entity, spec["engine"], spec["kind"]
        self.spec = spec
        self.action = action
        self.names, self.action_space = action_space(self.kind, action)
        self.route = route
        self.map_path, self.road_map, self.stop_lines = map_path, road_map, list(stop_lines)
        self.pts, self.cum = geometry.route_polyline({"points": route})
        self.wheelbase = 0.6 * spec["length"] if self.kind == "vehicle" else 1.0

    def start(self, teleport):
        """A new episode from `teleport` ({x, y, yaw, speed}: sent with the first step)."""
        self.state = None
        self.first = dict(teleport)
        self.pred = dict(teleport)   # where the commands put it (they are obeyed exactly)
        self.lane_change = None
        self.done = False
        self.collided = set()
        self.events = []
        self.live = LiveScore(self.route, self.map_path, self.stop_lines, ego=self.engine) if self.kind == "vehicle" else None
        self.progress_max = 0.0
        self.metrics = {"progress": 0.0, "new_infractions": [], "discomfort": 0.0, "route_offset": 0.0}

    def command(self, a):
        """The agent's command for action `a` (checked), from its last state."""
        if self.first is not None:
            cmd, self.first = {"teleport": self.first}, None
            return cmd
        if a is None:   # the neutral action: on at the same speed and heading
            a = {"controls": [0.0, 0.0, 0.0] if self.kind == "vehicle" else [self.pred["speed"], 0.0],
                 "target_speed_lane": [self.pred["speed"], 0.0][:len(self.names)]}[self.action]
        # from the state its commands gave it: the status function's states are those at the
        # start of the step just run, one step behind the commands (module docstring)
        u = self.pred
        v, yaw = float(u["speed"]), float(u["yaw"])
        if self.action == "controls" and self.kind == "vehicle":
            acc = MAX_ACCEL * a[0] - MAX_BRAKE * a[1]
            v1 = min(MAX_SPEED, max(0.0, v + acc * DT))
            yaw1 = yaw + v1 / self.wheelbase * math.tan(a[2]) * DT
            yaw1 = math.atan2(math.sin(yaw1), math.cos(yaw1))
            self.pred = {"x": u["x"] + v1 * math.cos(yaw1) * DT, "y": u["y"] + v1 * math.sin(yaw1) * DT,
                         "yaw": yaw1, "speed": v1}
            return {"trajectory": dict(self.pred)}
        if self.action == "controls":            # a pedestrian: walking speed, turn rate
            yaw1 = math.atan2(math.sin(yaw + a[1] * DT), math.cos(yaw + a[1] * DT))
            self.pred = {"x": u["x"] + a[0] * math.cos(yaw1) * DT, "y": u["y"] + a[0] * math.sin(yaw1) * DT,
                         "yaw": yaw1, "speed": float(a[0])}
            return {"trajectory": dict(self.pred)}
        limit = (MAX_ACCEL, MAX_BRAKE) if self.kind == "vehicle" else (1.5, 3.0)
        v1 = max(0.0, v + min(limit[0] * DT, max(-limit[1] * DT, a[0] - v)))
        self.pred = dict(self.pred, speed=v1)
        cmd = {"speed": {"speed": v1, "target_speed": float(a[0]), "acceleration": (v1 - v) / DT}}
        if self.kind == "vehicle":
            lane = self._lane(int(round(a[1])))
            if lane is not None:
                cmd["lane"] = lane
        return cmd

    def _lane(self, request):
        u = self.state or {}
        if self.lane_change is None and request != 0 and u.get("road") not in (None, "") and "x" in u:
            side = 1.0 if request > 0 else -1.0        # +1: to the left
            x = u["x"] - side * LANE_WIDTH * math.sin(u["yaw"])
            y = u["y"] + side * LANE_WIDTH * math.cos(u["yaw"])
            from convoy_bench import road_map
            w = road_map.locate(self.road_map, [x], [y], [u["yaw"]])[0]
            if (w["lane_type"] == "driving" and w["road"] == u["road"] and w["heading"] is not None
                    and math.cos(w["heading"] - u["yaw"]) > 0.5 and w["lane"] != u["lane"]):
                self.lane_change = {"road": str(u["road"]), "lane": int(w["lane"]),
                                    "from_lane": int(u["lane"]), "k": 0}
        lc = self.lane_change
        if lc is None:
            return None
        lc["k"] += 1
        p = min(1.0, lc["k"] * DT / LANE_CHANGE_S)
        if p >= 1.0:
            self.lane_change = None
        return {"road": lc["road"], "lane": lc["lane"], "from_lane": lc["from_lane"], "offset": 0.0,
                "progress": p}

    def observe(self, t, users, collisions, signals=None):
        """Updates the metrics with the step's states; collisions: [(a, b)] new this step;
        signals: the traffic lights' {id: state} (red lights are infractions)."""
        u = users.get(self.engine)
        if u is None:
            return
        self.state = u
        new = []
        for a, b in collisions:
            if self.engine in (a, b):
                other = b if a == self.engine else a
                cls = users[other].get("category", "car")
                kind = ("collision_pedestrian" if cls == "pedestrian" else
                        "collision_vehicle" if cls in ("car", "truck", "bus", "cyclist") else "collision_static")
                self.collided.add(other)
                if self.live is None:   # a pedestrian: its collisions, CARLA's factors
                    new.append({"t": t, "kind": kind, "other": other, "penalty": score.PENALTY[kind]})
                self.events.append({"t": t, "a": self.engine, "b": other, "class_a": u.get("category"),
                                    "class_b": cls})
        if self.live is not None:
            seen = len(self.live.events)
            others = {k: {"class": o.get("category", "car"), "x": o["x"], "y": o["y"], "yaw": o["yaw"],
                          "speed": o["speed"], "length": o.get("length", 0.0),
                          "length_offset": o.get("length_offset", 0.0)}
                      for k, o in sorted(users.items()) if k != self.engine and not o.get("absent")}
            self.live.add(t, u, others, self.events, signals)
            new += [{"t": e["t"], "kind": e["kind"], "other": e.get("other"),
                     "penalty": score.PENALTY.get(e["kind"], 1.0)} for e in self.live.events[seen:]]
            progress = max(0.0, self.live._s_max - self.live._off.value()) if self.live._pts is not None else 0.0
            p, dist, _ = geometry.project_on_polyline(self.pts, self.cum, u["x"], u["y"],
                                                      self.live._s_max - score.PROJECTION_BACK_M,
                                                      self.live._s_max + score.PROJECTION_AHEAD_M)
        else:
            p, dist, _ = geometry.project_on_polyline(self.pts, self.cum, u["x"], u["y"])
            self.progress_max = max(self.progress_max, p)
            progress = self.progress_max
        self.metrics = {"progress": float(progress), "new_infractions": new, "discomfort": discomfort(u),
                        "route_offset": float(dist), "route_s": float(p), "collided": bool(self.collided),
                        "absent": bool(u.get("absent"))}

    def observation(self, parts, users, radius):
        u = self.state
        out = {}
        c, s = math.cos(u["yaw"]), math.sin(u["yaw"])
        if "ego" in parts:
            yaw = math.atan2(s, c)
            out["ego"] = np.array([u["x"], u["y"], yaw, max(0.0, u["speed"]), u.get("acceleration", 0.0),
                                   u.get("yaw_rate", 0.0), self.metrics.get("route_offset", 0.0)],
                                  dtype=np.float32)
        if "road_users" in parts:
            rows = []
            for k, o in sorted(users.items()):
                if k == self.engine or o.get("absent"):
                    continue
                dx, dy = o["x"] - u["x"], o["y"] - u["y"]
                d = math.hypot(dx, dy)
                if d <= radius:
                    rel = math.atan2(math.sin(o["yaw"] - u["yaw"]), math.cos(o["yaw"] - u["yaw"]))
                    rows.append((d, k, [1.0, c * dx + s * dy, -s * dx + c * dy, rel, o["speed"],
                                        o.get("length", 0.0), o.get("width", 0.0),
                                        1.0 if o.get("category") == "pedestrian" else 0.0]))
            rows.sort(key=lambda r: (r[0], r[1]))
            table = np.zeros((N_USERS, len(USER_COLUMNS)), dtype=np.float32)
            for i, r in enumerate(rows[:N_USERS]):
                table[i] = r[2]
            out["road_users"] = table
        if "route" in parts:
            base = self.metrics.get("route_s", 0.0)
            pts = []
            for ahead in ROUTE_AHEAD:
                px, py = _point_at(self.pts, self.cum, base + ahead)
                dx, dy = px - u["x"], py - u["y"]
                pts.append([c * dx + s * dy, -s * dx + c * dy])
            out["route"] = np.array(pts, dtype=np.float32)
        return out


def _point_at(pts, cum, s):
    s = min(max(s, 0.0), float(cum[-1]))
    j = min(len(cum) - 2, max(0, int(np.searchsorted(cum, s, side="right")) - 1))
    seg = float(cum[j + 1] - cum[j]) or 1.0
    f = (s - float(cum[j])) / seg
    return (float(pts[j][0] + f * (pts[j + 1][0] - pts[j][0])), float(pts[j][1] + f * (pts[j + 1][1] - pts[j][1])))


class ScenarioSim:
    """One NRPCoreSim server running a scenario episode config with `learning` entities."""

    def __init__(self, scenario, learning=None, parameters=None, timeout=None, args="", log_output=""):
        self.nrp = None
        self.tmp = tempfile.mkdtemp(prefix="convoy_gym_scenario_")
        try:
            self.config, self.info = build_episode_config(scenario, self.tmp, learning, parameters, timeout)
            self.nrp = NrpCore(free_address(), experiment_folder=self.tmp, config_file=self.config,
                               args=args, log_output=log_output, local_channel=True)
            self.nrp.initialize()
        except BaseException:
            self.close()
            raise
        self.needs_reset = False
        self.raw = None
        self.seen_pairs = set()
        self.stop_lines = []
        if self.info.get("lights"):
            from convoy_scenario.stop_lines import stop_lines
            self.stop_lines = stop_lines(self.info["map"])

    def reset(self):
        if self.needs_reset:
            self.nrp.reset()
        self.needs_reset = True
        self.seen_pairs = set()
        self.raw = None

    def step(self, commands):
        """Sends {engine: command} and runs one step; returns the status function's dict and the
        collisions [(a, b)] that started in it (bounding boxes overlapping)."""
        for engine, cmd in sorted(commands.items()):
            self.nrp.set_json_datapack("command", engine, cmd)
        _, observations = self.nrp.run_loop(1)
        dicts = [o for o in observations if isinstance(o, dict)]
        if not dicts:
            raise RuntimeError("scenario episode: the status function returned no observation")
        self.raw = dicts[-1]
        users = self.raw["users"]
        boxes = {k: {"x": u["x"], "y": u["y"], "yaw": u["yaw"], "length": u.get("length", 0.0),
                     "width": u.get("width", 0.0), "length_offset": u.get("length_offset", 0.0)}
                 for k, u in users.items() if not u.get("absent")}
        pairs = {(a, b) for a, others in box_collisions(boxes).items() for b in others if a < b}
        new = sorted(pairs - self.seen_pairs)
        self.seen_pairs |= pairs
        return self.raw, new

    def close(self):
        nrp, self.nrp = getattr(self, "nrp", None), None
        tmp, self.tmp = getattr(self, "tmp", None), None
        try:
            if nrp is not None:
                nrp.shutdown()
        finally:
            if tmp:
                shutil.rmtree(tmp, ignore_errors=True)


def start_pose(spec, rng, start_offset, start_speed):
    """The start of a learning road user for one episode: moved ds in [-start_offset,
    start_offset] m along its Init heading, at a speed in [0, start_speed] m/s (its Init speed
    when start_speed is None), both drawn from rng."""
    x, y, yaw = spec["start"]
    ds = float(rng.uniform(-start_offset, start_offset)) if start_offset > 0 else 0.0
    v = float(spec["speed"]) if start_speed is None else float(rng.uniform(0.0, start_speed))
    return {"x": x + ds * math.cos(yaw), "y": y + ds * math.sin(yaw), "yaw": yaw, "speed": v}


def pedestrian_route(spec, length=100.0):
    x, y, yaw = spec["start"]
    return [[x, y], [x + length * math.cos(yaw), y + length * math.sin(yaw)]]
