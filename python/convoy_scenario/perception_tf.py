"""The reference agent's perception in a scenario run (make_config.py --perception;
docs/scenarios.md, "Perception: ground truth or sensors"), at the planner's rate.

The mode is the planner engine's CONVOY_PERCEPTION (EngineEnvParams), "ground_truth" when it
has none. It is written once into summary.json as `perception` (with `perception_label`), so
the run and the campaign's leaderboard say which perception drove the ego.

- ground_truth: nothing else here; traffic_tf.py gives the planner the world's road users.
- sensors: this function builds the planner's `planner_input` (source "sensors"; traffic_tf
  then leaves it out): the detector's boxes (its `detections`, from the camera's frames) ranged
  by the roof LiDAR's cloud (`<ego model>::base_link::roof_lidar`, the smart_car_lidar model),
  the camera's depth image when a box has too few returns (convoy_traffic.fusion), tracked
  over the detector's frames for velocities (ego_planner.Tracker); and, all around the ego,
  each new scan's clusters, tracked (convoy_sensors.surround: those the camera does not wholly
  see and no camera object explains, ranged_by "lidar_surround"; the camera's vehicles also
  take their cluster's lateral extent), so that the planner can change lanes. Traffic lights are not
  detected: a red (or too late yellow) light of the ego's approach comes from the lights
  engine's state as a standing object at its stop line, as traffic_tf does (labelled
  source "traffic_lights").

The counts (perception_boxes, perception_ranged_by_lidar / _depth, perception_rejected_by_lidar:
near boxes without LiDAR returns, dropped as phantoms; perception_lidar_only: obstacles in the
ego's way the LiDAR saw and no box explained, fusion.lidar_obstacles; perception_lidar_surround:
the surround objects, summed over scans) are written every simulated
second of detections. CONVOY_PERCEPTION_DUMP=N (debugging) saves the first N frames from
CONVOY_PERCEPTION_DUMP_FROM s on (default 0; the boxes, the cloud's x, y, z, label, instance and
flags, the fused objects) as RUN_DIR/perception_<frame>.npz."""

import math
import os
import sys

from nrp_core import *  # noqa: F401,F403
from nrp_core.data.nrp_json import JsonDataPack

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))
from convoy_bench.run_files import load_config, update_summary  # noqa: E402
from convoy_traffic.ego_planner import SOURCE_LABELS, Tracker, ego_state, objects_from_road_users  # noqa: E402

CONFIG = load_config()
ENGINES = CONFIG.get("EngineConfigs", [])
PLANNER = next(e for e in ENGINES if e.get("EngineName") == "planner")
MODE = next((p.split("=", 1)[1] for p in PLANNER.get("EngineEnvParams", [])
             if p.startswith("CONVOY_PERCEPTION=")), "ground_truth")
WORLD = next(e["EngineName"] for e in ENGINES if e.get("EngineType") == "gazebo_grpc")
DETECTOR = next((e["EngineName"] for e in ENGINES if e.get("EngineType") == "detector"), None)
LIGHTS = next((e for e in ENGINES if e.get("EngineType") == "traffic_lights"), None)
SCENARIO = next((e for e in ENGINES if e.get("EngineType") == "scenario"), None)
EGO_SPEC = ((SCENARIO or {}).get("Entities") or {}).get((SCENARIO or {}).get("EgoName", "Ego"), "")
EGO_WORLD, EGO_DP = EGO_SPEC.split("/", 1) if "/" in EGO_SPEC else (WORLD, "smart_car::road_user")
EGO_MODEL = EGO_DP.split("::", 1)[0]
LIDAR_DP = EGO_MODEL + "::base_link::roof_lidar"
CAMERA_DEPTH = "smart_camera::camera::depth"
STOP_LOOKAHEAD = 60.0    # m, as traffic_tf.py
YELLOW_STOP_DECEL = 3.0  # m/s^2, as traffic_tf.py

LABELS = {"ground_truth": SOURCE_LABELS["ground_truth"], "sensors": SOURCE_LABELS["sensors"]}
_state = {"written": False, "tracker": Tracker(), "frame": None, "objects": [],
          "ranged": {"lidar": 0, "depth": 0, "rejected": 0, "lidar_only": 0}, "boxes": 0, "last_write": 0.0,
          "surround": None, "scan_t": None, "surround_count": 0, "confirmer": None,
          "held": {"scenery": 0, "unconfirmed": 0}, "poses": [],
          "dump": int(os.environ.get("CONVOY_PERCEPTION_DUMP", "0") or 0),
          "dump_from": float(os.environ.get("CONVOY_PERCEPTION_DUMP_FROM", "0") or 0)}

if MODE == "sensors":
    import numpy as np  # noqa: E402
    from convoy_sensors.point_cloud import points  # noqa: E402
    from convoy_traffic.fusion import Rig, accepted, fuse, lidar_obstacles  # noqa: E402
    from convoy_sensors.surround import Surround  # noqa: E402
    from convoy_sensors.confirm import Confirmer  # noqa: E402
    RIG = Rig.smart_car_lidar()
    STOP_LINES = []
    if LIGHTS is not None:
        from convoy_scenario.stop_lines import stop_lines  # noqa: E402
        STOP_LINES = stop_lines(LIGHTS["Map"])


def stop_line_object(e, signals):
    """The ego's red light as a RoadUser dict standing at its stop line, or None."""
    reach = e["length_offset"] + 0.5 * e["length"]
    fx, fy = e["x"] + reach * math.cos(e["yaw"]), e["y"] + reach * math.sin(e["yaw"])
    for line in STOP_LINES:
        d = line.ahead(fx, fy, e["yaw"])
        if d is None or d < -0.5 or d > STOP_LOOKAHEAD:
            continue
        state = signals.get(line.id, "off")
        stop = state in ("red", "red_yellow") or (
            state == "yellow" and e["speed"] ** 2 <= 2.0 * YELLOW_STOP_DECEL * max(d, 0.0))
        if not stop:
            return None
        cx, cy = line.centre()
        return {"id": "stop_line:" + line.id, "category": "car",
                "x": cx + 0.1 * math.cos(line.heading), "y": cy + 0.1 * math.sin(line.heading),
                "yaw": line.heading, "length": 0.2, "width": 3.0, "length_offset": 0.0}
    return None


def _summary():
    fields = {"perception": MODE, "perception_label": LABELS.get(MODE, MODE)}
    if MODE == "sensors":
        fields["perception_boxes"] = _state["boxes"]
        fields["perception_ranged_by_lidar"] = _state["ranged"]["lidar"]
        fields["perception_ranged_by_depth"] = _state["ranged"]["depth"]
        fields["perception_rejected_by_lidar"] = _state["ranged"]["rejected"]
        fields["perception_lidar_only"] = _state["ranged"]["lidar_only"]
        fields["perception_lidar_surround"] = _state["surround_count"]
        fields["perception_dropped_on_scenery"] = _state["held"]["scenery"]
        fields["perception_unconfirmed"] = _state["held"]["unconfirmed"]
    update_summary(fields)


POSE_HISTORY_S = 1.0  # s of the ego's poses kept, to place a camera frame or a scan by its own time


def _remember(ego_msg, e):
    """Keeps the ego's pose by its state's simulation time (RoadUser.time_ns)."""
    raw = ego_msg.get("time_ns", 0) if isinstance(ego_msg, dict) else getattr(ego_msg, "time_ns", 0)
    t = float(raw or 0) * 1e-9
    poses = _state["poses"]
    if t <= 0.0:
        return   # no time on the state: the objects stay in the ego's frame now
    if not poses or t > poses[-1][0]:
        poses.append((t, e["x"], e["y"], e["yaw"]))
    while poses and poses[0][0] < t - POSE_HISTORY_S:
        poses.pop(0)


def pose_at(e, t):
    """The ego `e` at its pose of time t (s): the kept pose nearest in time (a camera frame or a
    scan is older than the ego's state; on a bend the ego has turned since, and a standing thing
    seen then would seem to slide sideways)."""
    if not _state["poses"]:
        return e
    tp, x, y, yaw = min(_state["poses"], key=lambda p: abs(p[0] - t))
    return dict(e, x=x, y=y, yaw=yaw)


def _scan_surround(e, scan):
    """A new LiDAR scan: its clusters all around the ego, tracked (convoy_sensors.surround)."""
    if scan is None or scan.isEmpty() or scan.data.time_ns == _state["scan_t"]:
        return
    _state["scan_t"] = scan.data.time_ns
    if _state["surround"] is None:
        _state["surround"] = Surround(RIG, e["length"], e["width"], e["length_offset"])
    p = points(scan)
    t = scan.data.time_ns * 1e-9
    _state["surround"].scan(np.stack([p["x"], p["y"], p["z"]], axis=1), p["flags"], t,
                            pose_at(e, t), intensity=p["intensity"])
    _state["surround_count"] += len(_state["surround"].objects(e, _state["objects"]))


def _sensors(ego, detections, scan, depth, lights):
    e = ego_state(ego.data)
    _remember(ego.data, e)
    _scan_surround(e, scan)
    det = None if detections is None or detections.isEmpty() else detections.data
    if det is not None and "detections" in det and det.get("frame") != _state["frame"]:
        _state["frame"] = det.get("frame")
        xyz = flags = None
        if scan is not None and not scan.isEmpty():
            p = points(scan)
            xyz = np.stack([p["x"], p["y"], p["z"]], axis=1)
            flags = p["flags"]
        dimg = None if depth is None or depth.isEmpty() else depth.data["depth"]
        boxes = list(det["detections"])
        objs = fuse(RIG, boxes, xyz, flags=flags, depth=dimg)
        objs += lidar_obstacles(RIG, xyz, flags, objects=accepted(objs))
        if _state["surround"] is not None:
            objs = _state["surround"].refine(objs)
        _state["boxes"] += len(boxes)
        for o in objs:
            _state["ranged"][o["ranged_by"]] += 1
        t = det.get("time_ns", 0) * 1e-9
        _state["objects"] = _confirmed(_state["tracker"].update(accepted(objs), t, e["speed"]), t, e)
        if t - _state["last_write"] >= 1.0:
            _state["last_write"] = t
            _summary()
        if _state["dump"] > 0 and t >= _state["dump_from"]:
            _state["dump"] -= 1
            _dump(boxes, scan, objs, e, t)
    objects = list(_state["objects"])
    if _state["surround"] is not None:
        objects += _state["surround"].objects(e, objects)
    signals = dict(lights.data["signals"]) if lights is not None and not lights.isEmpty() else {}
    line = stop_line_object(e, signals) if STOP_LINES else None
    if line is not None:
        objects += [dict(o, source="traffic_lights") for o in objects_from_road_users(e, [line])]
    return [JsonDataPack("planner_input", "planner", {"source": "sensors", "ego": e, "objects": objects})]


def _instance_classes(scan):
    """Ground truth, for the debugging dump only: {instance id: class} of the scan's points."""
    from convoy_sensors.point_cloud import instances
    if scan is None or scan.isEmpty():
        return {}
    return {str(k): cls for k, (_, cls) in instances(scan).items()}


def _confirmed(objects, t, e):
    """The tracked camera and LiDAR-only objects confirmed by the LiDAR's clusters or over
    frames (convoy_sensors.confirm); the others counted."""
    if _state["confirmer"] is None:
        _state["confirmer"] = Confirmer()
    e = pose_at(e, t)   # the camera frame's: the objects are in the ego's frame then
    boxes = _state["surround"].boxes_now(e) if _state["surround"] is not None else []
    out = _state["confirmer"].update(objects, t, e, boxes)
    for reason in _state["confirmer"].last.values():
        if reason in _state["held"]:
            _state["held"][reason] += 1
    return out


def _dump(boxes, scan, objs, e, t):
    import json
    p = points(scan) if scan is not None and not scan.isEmpty() else None
    path = os.path.join(os.environ.get("CONVOY_RUN_DIR", "."), "perception_%s.npz" % _state["frame"])
    fields = ("x", "y", "z", "intensity", "label", "instance", "flags")
    sur = _state["surround"].objects(e, _state["objects"]) if _state["surround"] is not None else []
    np.savez(path, boxes=json.dumps(boxes), objects=json.dumps(objs), tracked=json.dumps(_state["objects"]),
             surround=json.dumps(sur), ego=json.dumps(e), t=t, classes=json.dumps(_instance_classes(scan)),
             **({k: np.array(p[k]) for k in fields} if p is not None else {}))


def _perception(ego, detections=None, scan=None, depth=None, lights=None):
    if not _state["written"]:
        _state["written"] = True
        _summary()
    if MODE != "sensors" or ego.isEmpty():
        return []
    return _sensors(ego, detections, scan, depth, lights)


perception = _perception
if MODE == "sensors":
    if DETECTOR is None:
        raise RuntimeError("perception_tf: --perception sensors needs the detector engine (EngineType "
                           "detector) in the config")
    if LIGHTS is not None:
        perception = EngineDataPack(keyword="lights", id=DataPackIdentifier(
            "traffic_lights", LIGHTS["EngineName"]))(perception)
    perception = EngineDataPack(keyword="depth", id=DataPackIdentifier(CAMERA_DEPTH, WORLD))(perception)
    perception = EngineDataPack(keyword="scan", id=DataPackIdentifier(LIDAR_DP, WORLD))(perception)
    perception = EngineDataPack(keyword="detections", id=DataPackIdentifier("detections", DETECTOR))(perception)
perception = EngineDataPack(keyword="ego", id=DataPackIdentifier(EGO_DP, EGO_WORLD))(perception)
perception = TransceiverFunction("planner")(perception)
