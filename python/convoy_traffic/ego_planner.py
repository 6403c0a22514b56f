"""The ego's longitudinal planner: between perception and the report's PID waypoint follower.

It turns what the ego perceives into a target speed that the controller's TF applies to the
follower's rear wheels (the follower keeps steering):
- ACC: IDM gap control (v0, T, s0, a, b, delta) behind the nearest object in the ego's path;
- AEB: when the time to collision with an object in the path falls below `TtcAeb`, or the
  IDM command would not stop in time, the target speed is capped by a braking profile that
  stops `StopMargin` m before the object at up to `AebDeceleration` m/s^2.
- with a route and its lanes (ground truth or sensors): lane changes around stopped vehicles (MOBIL)
  and a cruise speed that follows faster traffic up to the limit: convoy_traffic.lane_change.

Objects come in the ego's frame (x forward from its reference point, y left) as dicts
{id, class, lon, lat, length, width, v_lon, v_lat, source}. Two sources build them:
- `objects_from_road_users` (ground truth: the world's RoadUsers), labelled "ground_truth";
- `objects_from_detections` (the detector's boxes, ranged in the camera's depth image),
  labelled "detections".

Used by experiments/ego_planner (ego_planner_engine.py, planner_input_*_tf.py); see
docs/architecture.md, "Ego planner".
"""

import json
import math
import tempfile

from convoy_traffic.lane_change import LANE_PARAMETERS, LaneChanger

SOURCES = ("ground_truth", "detections", "sensors")
SOURCE_LABELS = {"ground_truth": "ground-truth objects (the world's RoadUsers, not perception)",
                 "detections": "detector boxes ranged in the camera's depth image",
                 "sensors": "sensor perception: detector boxes ranged by LiDAR points (depth "
                            "image when too few), tracked (convoy_traffic.fusion), and LiDAR "
                            "clusters all around the ego, tracked (convoy_sensors.surround)"}

# key: (default, minimum, maximum)
PARAMETERS = {
    "CruiseSpeed": (30 / 3.6, 0.0, 60.0),      # m/s, IDM's v0
    "TimeGap": (1.2, 0.0, 10.0),               # s, IDM's T
    "StandstillDistance": (4.0, 0.5, 50.0),    # m, IDM's s0 (bumper to bumper)
    "MaxAcceleration": (1.5, 0.1, 10.0),       # m/s^2, IDM's a
    "ComfortDeceleration": (2.0, 0.1, 10.0),   # m/s^2, IDM's b
    "Delta": (4.0, 1.0, 10.0),                 # IDM's exponent
    "TtcAeb": (2.5, 0.1, 20.0),                # s: AEB below this time to collision
    "AebDeceleration": (6.0, 0.5, 12.0),       # m/s^2: the AEB braking profile
    "StopMargin": (3.0, 2.0, 20.0),            # m: AEB stops this far before the object
    "LateralMargin": (0.5, 0.0, 5.0),          # m: path corridor = ego half width + this
    "Range": (80.0, 5.0, 500.0),               # m: objects beyond are ignored
    "MinCrossingSpeed": (0.5, 0.0, 10.0),      # m/s: slower lateral motion predicts no entry
    "CrossingHorizon": (3.0, 0.0, 20.0),       # s: entries predicted further ahead are ignored
    "CommandSlack": (3.0, 0.1, 20.0),          # m/s: the command stays at most this above the speed
    "TraceRate": (10.0, 0.1, 1000.0),          # Hz of the speed trace in the output JSON
}
PARAMETERS.update(LANE_PARAMETERS)   # lane changes (convoy_traffic.lane_change)
KEYS = set(PARAMETERS) | {"Input", "Output"}
# The road-user classes (docs/road_users.md) the planner reacts to; scenery (buildings, trees,
# parked models' other classes) is not in the path's concern. COCO names a detector may give
# are mapped onto them.
ROAD_USER_CLASSES = ("car", "truck", "bus", "pedestrian", "cyclist")
COCO_TO_CLASS = {"person": "pedestrian", "bicycle": "cyclist", "motorcycle": "cyclist"}
EPISODE_GAP_S = 2.0  # a pedestrian stop episode ends when none was ahead for this long


class PlannerConfigError(ValueError):
    pass


def parse_config(cfg, engine="ego_planner"):
    """Validated parameters from a dict; raises PlannerConfigError naming engine and key."""
    if not isinstance(cfg, dict):
        raise PlannerConfigError("%s: the planner config must be a JSON object" % engine)
    for k in cfg:
        if k not in KEYS:
            raise PlannerConfigError("%s: unknown key '%s' (known: %s)"
                                     % (engine, k, ", ".join(sorted(KEYS))))
    out = {}
    src = cfg.get("Input", "ground_truth")
    if src not in SOURCES:
        raise PlannerConfigError("%s: key 'Input': unknown input source %r (expected one of: %s)"
                                 % (engine, src, ", ".join(SOURCES)))
    out["Input"] = src
    out["Output"] = cfg.get("Output", "ego_planner.json")
    if not isinstance(out["Output"], str) or not out["Output"]:
        raise PlannerConfigError("%s: key 'Output': expected a file name" % engine)
    for k, (default, lo, hi) in PARAMETERS.items():
        v = cfg.get(k, default)
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
            raise PlannerConfigError("%s: key '%s': expected a number, got %r" % (engine, k, v))
        if v < lo or v > hi:
            raise PlannerConfigError("%s: key '%s': %r is out of range [%g, %g]"
                                     % (engine, k, v, lo, hi))
        out[k] = float(v)
    return out


def _g(u, k, default=0.0):
    return u.get(k, default) if isinstance(u, dict) else getattr(u, k, default)


def ego_state(u):
    """The ego's RoadUser (message or dict) as a plain dict."""
    keys = ("x", "y", "yaw", "speed", "yaw_rate", "length", "width", "length_offset")
    d = {k: float(_g(u, k, 0.0) or 0.0) for k in keys}
    d["id"] = str(_g(u, "id", "ego"))
    return d


def objects_from_road_users(ego, users):
    """Ground-truth objects in the ego's frame from RoadUsers (messages or dicts)."""
    c, s = math.cos(ego["yaw"]), math.sin(ego["yaw"])
    out = []
    for u in users:
        uid = str(_g(u, "id", ""))
        if uid == ego["id"] or _g(u, "absent", False):
            continue
        yaw = float(_g(u, "yaw", 0.0))
        off = float(_g(u, "length_offset", 0.0))
        cx = float(_g(u, "x")) + off * math.cos(yaw) - ego["x"]
        cy = float(_g(u, "y")) + off * math.sin(yaw) - ego["y"]
        vx, vy = float(_g(u, "vx", 0.0)), float(_g(u, "vy", 0.0))
        if vx == 0.0 and vy == 0.0:
            sp = float(_g(u, "speed", 0.0))
            vx, vy = sp * math.cos(yaw), sp * math.sin(yaw)
        rel = yaw - ego["yaw"]
        length = float(_g(u, "length", 0.0)) or 0.5
        width = float(_g(u, "width", 0.0)) or 0.5
        # the box's extent along and across the ego's axis
        ext_lon = abs(math.cos(rel)) * length + abs(math.sin(rel)) * width
        ext_lat = abs(math.sin(rel)) * length + abs(math.cos(rel)) * width
        out.append({"id": uid, "class": str(_g(u, "category", "") or "unknown"),
                    "lon": c * cx + s * cy, "lat": -s * cx + c * cy,
                    "length": ext_lon, "width": ext_lat,
                    "v_lon": c * vx + s * vy, "v_lat": -s * vx + c * vy,
                    "source": "ground_truth"})
    return out


def objects_from_detections(detections, depth, width, height, hfov, cam_x=0.0, cam_y=0.0,
                            percentile=15.0):
    """Objects in the ego's frame from the detector's boxes (pixels) ranged in a depth image
    (metres along the optical axis; numpy array height x width). The camera looks along the
    ego's x axis from (cam_x, cam_y); an object's range is the given percentile of the
    finite depths inside its box (the box also holds background). Velocities are 0 here; the
    Tracker estimates them."""
    import numpy as np
    f = (width / 2.0) / math.tan(hfov / 2.0)
    out = []
    for i, d in enumerate(detections):
        x0 = max(0, int(math.floor(d["x_min"])))
        x1 = min(width, int(math.ceil(d["x_max"])))
        y0 = max(0, int(math.floor(d["y_min"])))
        y1 = min(height, int(math.ceil(d["y_max"])))
        if x1 <= x0 or y1 <= y0:
            continue
        patch = depth[y0:y1, x0:x1]
        vals = patch[np.isfinite(patch) & (patch > 0)]
        if vals.size == 0:
            continue
        z = float(np.percentile(vals, percentile))
        u = (x0 + x1) / 2.0
        lat = -(u - width / 2.0) / f * z
        w = (x1 - x0) / f * z
        cls = str(d.get("class", "unknown"))
        cls = COCO_TO_CLASS.get(cls, cls)
        length = 0.5 if cls in ("pedestrian", "person", "cyclist") else 1.0
        out.append({"id": "%s#%d" % (cls, i), "class": cls,
                    "lon": cam_x + z + length / 2, "lat": cam_y + lat,
                    "length": length, "width": w, "v_lon": 0.0, "v_lat": 0.0,
                    "source": "detections"})
    return out


MAX_WALKER_SPEED = 4.0  # m/s: a pedestrian track's raw velocity is clamped to it


class Tracker:
    """Velocities for detections: each object is matched to the nearest one of its class in
    the previous frame (within `gate` m); its velocity is a filtered difference (a
    pedestrian's raw difference clamped to MAX_WALKER_SPEED). Ids become track ids."""

    def __init__(self, gate=2.5, alpha=0.3):
        self.gate, self.alpha = gate, alpha
        self.tracks = {}
        self.next_id = 0
        self.t = None

    def update(self, objects, t, ego_speed):
        dt = None if self.t is None else t - self.t
        self.t = t
        new = {}
        for o in sorted(objects, key=lambda o: o["lon"]):
            best, best_d = None, self.gate
            for tid, tr in self.tracks.items():
                if tid in new or tr["class"] != o["class"]:
                    continue
                dd = math.hypot(tr["lon"] - o["lon"], tr["lat"] - o["lat"])
                if dd < best_d:
                    best, best_d = tid, dd
            if best is None or not dt:
                tid = best if best is not None else "track%d" % self.next_id
                if best is None:
                    self.next_id += 1
                # a new object: assumed standing (relative speed -ego speed)
                v_lon = self.tracks[best]["v_lon"] if best is not None else 0.0
                v_lat = self.tracks[best]["v_lat"] if best is not None else 0.0
            else:
                tid, tr = best, self.tracks[best]
                # absolute velocity = relative rate + the ego's own speed
                raw_lon = (o["lon"] - tr["lon"]) / dt + ego_speed
                raw_lat = (o["lat"] - tr["lat"]) / dt
                if o["class"] == "pedestrian":
                    # No one walks faster than MAX_WALKER_SPEED: more is the depth ranging
                    # jumping (a box taking in more or less background), not motion.
                    raw = math.hypot(raw_lon, raw_lat)
                    if raw > MAX_WALKER_SPEED:
                        raw_lon, raw_lat = raw_lon * MAX_WALKER_SPEED / raw, raw_lat * MAX_WALKER_SPEED / raw
                v_lon = tr["v_lon"] + self.alpha * (raw_lon - tr["v_lon"])
                v_lat = tr["v_lat"] + self.alpha * (raw_lat - tr["v_lat"])
            o = dict(o, id=tid, v_lon=v_lon, v_lat=v_lat)
            new[tid] = o
        self.tracks = new
        return [new[k] for k in sorted(new)]


NEAR_FIELD_M = 5.0  # gap within which the ego's own heading decides, route or not


class Planner:
    def __init__(self, params, route=None, lanes=None):
        """`route`: a route_path.RoutePath in the world frame, or None: the path is then the
        ego's current curvature (its yaw rate over its speed). `lanes`: a lanes.RouteLanes of
        the route: with it (and LaneChange 1, ground-truth or sensor input) the ego passes stopped
        vehicles by a lane change (convoy_traffic.lane_change)."""
        self.p = params
        self.route = route
        self.lc = None
        if route is None or lanes is None:
            self.lane_change = "off (no route or no map)"
        elif not params["LaneChange"]:
            self.lane_change = "off (LaneChange 0)"
        elif params["Input"] == "detections":
            # a lane change needs the lane behind the ego: the camera's perception looks ahead only
            # ("sensors" adds the roof LiDAR's objects all around: convoy_sensors.surround)
            self.lane_change = "off (input %s sees nothing behind the ego)" % params["Input"]
        else:
            self.lane_change = "on"
            self.lc = LaneChanger(params, route, lanes)
        self._route_s = None  # the ego's last arc length on the route
        self.v_cmd = None
        self.stop_events = []       # ego stopped / AEB-braked because of a pedestrian
        self._episode_last = None   # last time a pedestrian led in the current stop episode
        self.min_ped_distance = None
        self.min_ped_distance_stopped = None
        self.min_gap = None
        self.aeb_active_s = 0.0
        self.max_decel = 0.0
        # The speed trace goes to an unlinked temporary file, a JSON line per sample, so that the
        # planner's memory stays flat however long the run; result() reads it back.
        self._trace = tempfile.TemporaryFile(mode="w+", prefix="convoy-planner-trace-")
        self._last_trace_t = None
        self._prev_speed = None

    def in_path(self, ego, o):
        """(in path, gap in m from the ego's front to the object's near edge)."""
        p = self.p
        front = ego["length_offset"] + ego["length"] / 2
        gap = o["lon"] - o["length"] / 2 - front
        if o["lon"] < 0 or gap > p["Range"]:
            return False, gap
        kappa = ego["yaw_rate"] / ego["speed"] if ego["speed"] > 1.0 else 0.0
        lat = o["lat"] - kappa * o["lon"] ** 2 / 2  # the ego's path bends with its yaw rate
        v_lat = o["v_lat"]
        if self.route is not None and gap > NEAR_FIELD_M:
            gap, lat, v_lat = self._on_route(ego, o, front)
            if gap is None:
                return False, o["lon"] - o["length"] / 2 - front
        half = (ego["width"] or 1.8) / 2 + p["LateralMargin"]
        clearance = abs(lat) - o["width"] / 2 - half
        if clearance <= 0:
            return True, gap
        toward = -v_lat if lat > 0 else v_lat
        if toward < max(p["MinCrossingSpeed"], 0.01):
            return False, gap
        # it enters the corridor soon, and before the ego has passed it (1 s of slack)
        t_enter = clearance / toward
        closing = max(ego["speed"] - o["v_lon"], 0.1)
        return t_enter <= min(p["CrossingHorizon"], max(gap, 0.0) / closing + 1.0), gap

    def route_position(self, ego):
        """The ego's arc length on the route, followed from step to step."""
        if self._route_s is None:
            s, _ = self.route.locate(ego["x"], ego["y"])
        else:
            s, _ = self.route.locate(ego["x"], ego["y"], self._route_s - 5.0, self._route_s + 50.0)
        self._route_s = s
        return s

    def _on_route(self, ego, o, front):
        """(gap along the route, distance from it, speed towards its left) of object `o` (in
        the ego's frame), or (None, None, None) when it is not on the route ahead."""
        c, sn = math.cos(ego["yaw"]), math.sin(ego["yaw"])
        ox = ego["x"] + c * o["lon"] - sn * o["lat"]
        oy = ego["y"] + sn * o["lon"] + c * o["lat"]
        s_ego = self.route_position(ego)
        s_obj, d = self.route.locate(ox, oy, s_ego - 1.0, s_ego + self.p["Range"] + 20.0)
        if s_obj <= s_ego or s_obj >= self.route.length:
            return None, None, None
        h = self.route.heading(s_obj) - ego["yaw"]
        v_left = -math.sin(h) * o["v_lon"] + math.cos(h) * o["v_lat"]
        if self.lc is not None:
            d -= self.lc.offset_at(s_obj)   # the path is the route offset by a lane change
        return s_obj - s_ego - o["length"] / 2 - front, d, v_left

    def step(self, t, ego, objects):
        p = self.p
        v = max(ego["speed"], 0.0)
        if self.v_cmd is None:
            self.v_cmd = v
        steer = None
        v0 = max(p["CruiseSpeed"], 0.01)
        if self.lc is not None:
            users = [o for o in objects if o["class"] in ROAD_USER_CLASSES]
            steer = self.lc.update(t, ego, self.route_position(ego), users, p["CruiseSpeed"])
            v0 = max(self.lc.v0, 0.01)   # the traffic's flow (lane_change.flow_speed)
        lead, lead_gap = None, None
        for o in objects:
            if o["class"] not in ROAD_USER_CLASSES:
                continue
            ok, gap = self.in_path(ego, o)
            if ok and (lead_gap is None or gap < lead_gap):
                lead, lead_gap = o, gap
            if o["class"] == "pedestrian" and ok:
                if self.min_ped_distance is None or gap < self.min_ped_distance:
                    self.min_ped_distance = gap
        # IDM
        acc = p["MaxAcceleration"] * (1 - (v / v0) ** p["Delta"])
        ttc = None
        mode = "cruise"
        if lead is not None:
            dv = v - lead["v_lon"]
            s = max(lead_gap, 0.01)
            s0 = p["StandstillDistance"]
            if self.lc is not None and lead["id"] == self.lc.standoff_id:
                s0 += p["LaneChangeStandoff"]   # room to pull out once the next lane is free
            s_star = s0 + max(
                0.0, v * p["TimeGap"] + v * dv / (2 * math.sqrt(p["MaxAcceleration"] *
                                                               p["ComfortDeceleration"])))
            acc -= p["MaxAcceleration"] * (s_star / s) ** 2
            mode = "follow"
            if dv > 0.05:
                ttc = lead_gap / dv
        dt = 0.0 if getattr(self, "_t", None) is None else t - self._t
        self._t = t
        cmd = self.v_cmd + acc * dt
        cmd = min(cmd, v + p["CommandSlack"], v0)  # no floor: braking is not delayed
        # AEB: brake to stop StopMargin before the object
        aeb = False
        if lead is not None:
            room = max(lead_gap - p["StopMargin"], 0.0)
            v_allowed = math.sqrt(2 * p["AebDeceleration"] * room) + max(lead["v_lon"], 0.0)
            need = v * v / (2 * room) if room > 0 else float("inf")
            if (ttc is not None and ttc < p["TtcAeb"]) or need > p["ComfortDeceleration"]:
                aeb = v > 0.3  # an emergency: brake along the profile at the least
                cmd = min(cmd, v_allowed)
            if lead_gap <= p["StopMargin"] and lead["v_lon"] < 0.5:
                cmd = 0.0
                aeb = aeb or v > 0.3
        if aeb:
            mode = "aeb"
            self.aeb_active_s += dt
        self.v_cmd = max(cmd, 0.0)
        if lead is not None:
            self.min_gap = lead_gap if self.min_gap is None else min(self.min_gap, lead_gap)
        # pedestrian stop events: one per episode (the ego stopped or AEB-braked with a
        # pedestrian as the object it reacts to; the episode ends when no pedestrian has led
        # for EPISODE_GAP_S, so track ids changing under a detector do not count twice)
        if lead is not None and lead["class"] == "pedestrian":
            stopped = v < 0.1
            in_episode = (self._episode_last is not None
                          and t - self._episode_last <= EPISODE_GAP_S)
            if in_episode:
                self._episode_last = t
            elif aeb or stopped:
                self._episode_last = t
                self.stop_events.append({"t": round(t, 3), "pedestrian": lead["id"],
                                         "reason": "aeb" if aeb else "stopped",
                                         "gap_m": round(lead_gap, 3), "speed_mps": round(v, 3)})
            if stopped:
                d = lead_gap
                if self.min_ped_distance_stopped is None or d < self.min_ped_distance_stopped:
                    self.min_ped_distance_stopped = d
        if self._prev_speed is not None and dt > 0:
            self.max_decel = max(self.max_decel, (self._prev_speed - v) / dt)
        self._prev_speed = v
        if self._last_trace_t is None or t - self._last_trace_t >= 1.0 / p["TraceRate"] - 1e-9:
            self._last_trace_t = t
            self._trace.write(json.dumps(
                {"t": round(t, 3), "speed_mps": round(v, 3),
                 "target_mps": round(self.v_cmd, 3), "mode": mode,
                 "lead": lead["id"] if lead else None,
                 "lead_class": lead["class"] if lead else None,
                 "gap_m": round(lead_gap, 3) if lead else None,
                 "lead_speed_mps": round(lead["v_lon"], 3) if lead else None,
                 "steer": round(steer, 4) if steer is not None else None}) + "\n")
        return {"speed": self.v_cmd, "mode": mode, "lead": lead["id"] if lead else None,
                "gap_m": lead_gap, "ttc_s": ttc, "steer": steer}

    def result(self):
        src = self.p["Input"]
        return {"input": src, "input_label": SOURCE_LABELS[src],
                "ground_truth": src == "ground_truth",
                "path": "route" if self.route is not None else "curvature",
                "ego_stops_for_pedestrians": len(self.stop_events),
                "pedestrian_stop_events": self.stop_events,
                "min_distance_to_pedestrian_m": self.min_ped_distance,
                "min_distance_to_pedestrian_stopped_m": self.min_ped_distance_stopped,
                "min_gap_to_lead_m": self.min_gap,
                "aeb_active_s": round(self.aeb_active_s, 3),
                "max_deceleration_mps2": round(self.max_decel, 3),
                "lane_change": self.lane_change,
                "lane_changes": self.lc.events if self.lc is not None else [],
                "max_cruise_speed_mps": round(self.lc.max_v0 if self.lc else self.p["CruiseSpeed"], 3),
                "parameters": {k: self.p[k] for k in sorted(PARAMETERS)},
                "speed_trace": self.trace}

    @property
    def trace(self):
        """The speed trace so far: a dict per sample."""
        self._trace.seek(0)
        rows = [json.loads(line) for line in self._trace]
        self._trace.seek(0, 2)
        return rows
