"""Scores a city_traffic run folder (docs/scoring.md, "Run folders"): reads what the recorder
(experiments/city_traffic/recorder.py) wrote and feeds score.score_drive. Only reads.

What it reads:
- tracks.jsonl: one row per 20 Hz step {"t", "users": [[id, class, x, y, yaw, speed, length,
  length_offset], ...], "signals", "target"}. The ego is the road user the recorder calls
  EGO ("smart_car"); the others are everyone else in the row.
- summary.json: "collisions" (the world engine's {"t", "a", "b", "class_a", "class_b",
  "relative_speed_mps"}, each contact once when it starts) and "red_light_violation_list"
  ({"t", "id", "signal", ...}). Missing: no collisions and red lights are known.
- config.json: the ego follower's CONVOY_EGO_ROUTE / CONVOY_EGO_ROUTE_SKIP (EngineEnvParams of
  the engine running ego_driver.py), to pick the route the ego drove.

What it derives:
- route: route_csv, else the run's CONVOY_EGO_ROUTE (a file of experiments/city_traffic), else
  experiments/city_traffic/ego_route.csv (x, y, heading columns); cut at the point nearest to
  the ego's first position (ego_driver.py follows it from the car's start).
- per sample, from experiments/city_traffic/city.xodr (road_map): on_road, wrong_way (in a
  driving lane outside a junction whose direction of travel differs from the ego's heading by
  more than 120 deg, CARLA's MAX_VEHICLE_ANGLE), in_junction, multiple_lanes (the ego's box
  corners in different lanes outside junctions), speed_limit; on_route is not set (outside
  route lanes = off the road or wrong way, as CARLA's OutsideRouteLanesTest).
- ttc: nuplan.ttc_at against every other road user (box widths by class: nuplan.DEFAULT_SIZE;
  the ego's width is the smart car's 1.8 m across its wheels); others that collided with the
  ego are left out afterwards, as nuPlan does.
- traffic_speed: the mean speed of the other road users that are not pedestrians.
- events: collisions involving the ego (other pedestrian -> collision_pedestrian; car, truck,
  bus, cyclist -> collision_vehicle; anything else, the world's static models ->
  collision_static) with the other's tracked state at that time; the ego's red-light
  violations.
"""

import bisect
import csv
import json
import math
import os

from . import geometry, nuplan, road_map, score

EGO = "smart_car"   # experiments/city_traffic/recorder.py EGO
EGO_WIDTH = 1.8     # m: the smart car's wheels (experiments/city_traffic/models/smart_car)
WRONG_WAY_ANGLE = math.radians(120.0)
VEHICLE_CLASSES = ("car", "truck", "bus", "cyclist")
HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
CITY = os.path.join(REPO, "experiments", "city_traffic")
NOT_IN_RUN_FOLDERS = [
    "stop_sign: the city has no stop signs and the recorder no stop-sign check",
    "scenario_timeout, yield_emergency: no CARLA scenarios or emergency vehicles in city_traffic",
    "on_route flags: outside route lanes is derived from the map (off the road, wrong way)",
    "drivable area: the ego's centre against the driving lanes (+0.5 m), not its corners",
    "nuPlan expert trajectory: the expert's progress is the route's length ahead of the ego",
    "box widths of road users: not recorded, taken by class",
]


def read_tracks(path):
    """The rows of tracks.jsonl in time order (a row not later than the previous is skipped)."""
    rows = []
    with open(path) as f:
        for n, line in enumerate(f, 1):
            line = line.strip()
            if not line:
                continue
            try:
                row = json.loads(line)
                t = float(row["t"])
            except (ValueError, KeyError, TypeError) as e:
                raise ValueError("%s:%d: %s" % (path, n, e)) from None
            if rows and t <= rows[-1]["t"]:
                continue
            row["t"] = t
            rows.append(row)
    return rows


def read_route_csv(path, skip=0):
    """The x, y points of a route CSV (convoy-odr route: x, y, heading columns)."""
    with open(path) as f:
        try:
            pts = [[float(r["x"]), float(r["y"])] for r in csv.DictReader(f)]
        except (KeyError, TypeError, ValueError) as e:
            raise ValueError("%s: bad row (%s)" % (path, e)) from None
    return pts[skip:]


def _run_route(run_dir):
    """(path, skip) of the route the run's ego follower was given, from config.json."""
    try:
        with open(os.path.join(run_dir, "config.json")) as f:
            engines = json.load(f).get("EngineConfigs", [])
    except (OSError, ValueError):
        return None
    for e in engines:
        if not str(e.get("PythonFileName", "")).endswith("ego_driver.py"):
            continue
        env = dict(p.split("=", 1) for p in e.get("EngineEnvParams", []) if "=" in p)
        if "CONVOY_EGO_ROUTE" in env:
            return os.path.join(CITY, os.path.basename(env["CONVOY_EGO_ROUTE"])), int(env.get("CONVOY_EGO_ROUTE_SKIP", "0"))
    return None


def cut_route(points, x, y):
    """The route from the point nearest to (x, y) on."""
    pts, cum = geometry.route_polyline(points)
    s, _, _ = geometry.project_on_polyline(pts, cum, x, y)
    j = int(max(0, min(len(pts) - 2, (cum <= s).sum() - 1)))
    u = (s - cum[j]) / (cum[j + 1] - cum[j])
    start = pts[j] + u * (pts[j + 1] - pts[j])
    rest = [p for p, c in zip(pts.tolist(), cum) if c > s]
    return [start.tolist()] + rest


def _collision_events(summary, states_at):
    out = []
    for c in summary.get("collisions") or []:
        a, b = c.get("a"), c.get("b")
        if EGO not in (a, b) or a == b:
            continue
        other, cls = (b, c.get("class_b")) if a == EGO else (a, c.get("class_a"))
        kind = ("collision_pedestrian" if cls == "pedestrian" else
                "collision_vehicle" if cls in VEHICLE_CLASSES else "collision_static")
        t = float(c["t"])
        e = {"t": t, "kind": kind, "other": other, "other_class": cls}
        state = states_at(t).get(other)
        if state is not None:
            e["other_state"] = state
        out.append(e)
    return out


def score_run(run_dir, route_csv=None, ego=EGO, map_path=None):
    """score.score_drive's result for a city_traffic run folder, with "run": what was read,
    computed and not available."""
    tracks = read_tracks(os.path.join(run_dir, "tracks.jsonl"))
    summary, missing = {}, list(NOT_IN_RUN_FOLDERS)
    try:
        with open(os.path.join(run_dir, "summary.json")) as f:
            summary = json.load(f)
    except OSError:
        missing.insert(0, "summary.json: no collisions or red-light violations known")
    except ValueError as e:
        raise ValueError("summary.json: %s" % e) from None

    samples, others_at, times = [], [], []
    for row in tracks:
        users = row.get("users") or []
        mine = [u for u in users if u[0] == ego]
        if not mine:
            continue
        _, cls, x, y, yaw, speed, length, loff = mine[0][:8]
        samples.append({"t": row["t"], "x": float(x), "y": float(y), "yaw": float(yaw), "speed": float(speed),
                        "length": float(length), "width": EGO_WIDTH, "length_offset": float(loff)})
        others = {}
        for u in users:
            if u[0] == ego:
                continue
            others[u[0]] = {"class": u[1], "x": float(u[2]), "y": float(u[3]), "yaw": float(u[4]),
                            "speed": float(u[5]), "length": float(u[6]), "length_offset": float(u[7])}
        others_at.append(others)
        times.append(row["t"])
    if len(samples) < 2:
        raise ValueError("%s: the ego %r is in fewer than two rows of tracks.jsonl" % (run_dir, ego))

    if route_csv is not None:
        route_path, skip = route_csv, 0
    else:
        route_path, skip = _run_route(run_dir) or (os.path.join(CITY, "ego_route.csv"), 0)
    route = {"points": cut_route(read_route_csv(route_path, skip), samples[0]["x"], samples[0]["y"])}

    m = road_map.load(map_path or os.path.join(CITY, "city.xodr"))
    xs = [s["x"] for s in samples]
    ys = [s["y"] for s in samples]
    yaws = [s["yaw"] for s in samples]
    where = road_map.locate(m, xs, ys, yaws)
    corners = geometry.box_corners(xs, ys, yaws, [s["length"] for s in samples], EGO_WIDTH,
                                   [s["length_offset"] for s in samples])
    corner_where = [road_map.locate(m, corners[:, k, 0], corners[:, k, 1], yaws) for k in range(4)]
    for i, (s, w) in enumerate(zip(samples, where)):
        lanes = {(c[i]["road"], c[i]["lane"]) for c in corner_where}
        in_junction = w["junction"] or any(c[i]["junction"] for c in corner_where)
        wrong = (w["lane_type"] == "driving" and not w["junction"] and w["heading"] is not None and
                 math.cos(w["heading"] - s["yaw"]) < math.cos(WRONG_WAY_ANGLE))
        s.update({"road": w["road"], "lane": w["lane"], "on_road": w["on_road"], "wrong_way": wrong,
                  "in_junction": in_junction, "multiple_lanes": len(lanes) > 1 and not in_junction,
                  "speed_limit": w["speed_limit"]})

    def states_at(t):
        return others_at[max(0, bisect.bisect_right(times, t) - 1)]

    events = _collision_events(summary, states_at)
    for v in summary.get("red_light_violation_list") or []:
        if v.get("id") == ego:
            events.append({"t": float(v["t"]), "kind": "red_light", "other": v.get("signal")})

    collided = {}
    for e in events:
        if e["kind"].startswith("collision_") and e["other"] not in collided:
            collided[e["other"]] = e["t"]
    for s, others in zip(samples, others_at):
        active = [o for oid, o in sorted(others.items()) if not (oid in collided and collided[oid] < s["t"])]
        wide = s["multiple_lanes"] or s["in_junction"] or not s["on_road"]
        s["ttc"] = nuplan.ttc_at(s, active, wide=wide)
        vehicles = [o["speed"] for _, o in sorted(others.items()) if o["class"] in VEHICLE_CLASSES]
        s["traffic_speed"] = math.fsum(vehicles) / len(vehicles) if vehicles else None

    result = score.score_drive(samples, route, events)
    result["run"] = {"run_dir": os.path.abspath(run_dir), "ego": ego, "samples": len(samples),
                     "t_first": samples[0]["t"], "t_last": samples[-1]["t"],
                     "route_csv": os.path.abspath(route_path), "route_skip": skip,
                     "recorder_min_ttc_s": summary.get("min_ttc_s"),
                     "collisions_in_summary": len(summary.get("collisions") or []),
                     "not_available": missing}
    return result
