"""The city experiment's recorder (a python_json engine). It writes into the run folder:

  camera.mp4      the ego's camera (30 Hz) with the detector's boxes drawn
  birds_eye.png   every road user's track over the city road, coloured by class
  tracks.jsonl    every road user's state at 20 Hz (id, class, x, y, yaw, speed)
  summary.json    participants (count by engine type), collisions, min_ttc_s,
                  red_light_violations, ego_stops_for_pedestrians, camera and detection rates

It is listed after the planner in the config: engines shut down in config order, so the
planner's ego_planner.json (its ego_stops_for_pedestrians) is written when this one reads it."""
import hashlib
import json
import math
import os
import sys
import time

import cv2
import numpy as np
from convoy_video import VideoWriter
from nrp_core.engines.python_json import EngineScript

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import city_map  # noqa: E402
import make_config  # noqa: E402

FPS = 30
COLOURS = {"car": (40, 40, 220), "truck": (0, 120, 200), "bus": (0, 160, 255),
           "pedestrian": (200, 60, 200), "cyclist": (0, 170, 0)}  # BGR
EGO = "smart_car"
# birds_eye.png's extent (m) and scale: the tracks are drawn onto it as the run goes, so that
# the recorder's memory stays flat however long the run (no list of every point)
X0, X1, Y0, Y1 = -260.0, 460.0, -160.0, 160.0
SCALE = 2.0  # px per m
# Another map (the large pooled city): $CONVOY_CITY_MAP (an .xodr here; the extent is its
# header's, 10 m round) and $CONVOY_CITY_ROAD (its road model under share/convoy/models).
MAP = os.environ.get("CONVOY_CITY_MAP", make_config.MAP)
ROAD_MODEL = os.environ.get("CONVOY_CITY_ROAD", "city_road")


def _use_extent_of(path):
    global X0, X1, Y0, Y1
    import xml.etree.ElementTree as ET
    h = ET.parse(path).getroot().find("header")
    X0, X1 = float(h.get("west")) - 10, float(h.get("east")) + 10
    Y0, Y1 = float(h.get("south")) - 10, float(h.get("north")) + 10


def px(x, y):
    return int(round((x - X0) * SCALE)), int(round((Y1 - y) * SCALE))


def load_obj(path):
    verts, faces = [], []
    with open(path) as f:
        for line in f:
            if line.startswith("v "):
                verts.append([float(v) for v in line.split()[1:3]])
            elif line.startswith("f "):
                faces.append([int(p.split("/")[0]) - 1 for p in line.split()[1:]])
    return np.array(verts), faces


class Script(EngineScript):
    def initialize(self):
        self._registerDataPack("traffic")
        self._registerDataPack("observation")
        self.dir = os.environ.get("CONVOY_RUN_DIR", ".")
        self.map = city_map.CityMap(os.path.join(HERE, MAP))
        if MAP != make_config.MAP:
            _use_extent_of(os.path.join(HERE, MAP))
        self.seen = set()         # every road user's id
        self.last_px = {}         # id -> its last drawn pixel
        self.ego_px = []          # the ego's track (drawn last, thick), a point per metre
        self.tracks_img = None    # the other road users' tracks, drawn as they move
        self.tracks_file = open(os.path.join(self.dir, "tracks.jsonl"), "w")
        self.digest = hashlib.sha1()
        self.prev_ahead = {}      # (id, line id) -> distance before the line at the last step
        self.violations = []
        self.crossed_on_red = {}  # (id, signal) -> the light was red when its front crossed the line
        self.min_ttc = None
        self.video = None
        self.frames = 0
        self.last_key = None
        self.detections = 0
        self.detector_frames = 0
        self.last_det_key = None
        self.collisions = []
        self.sumo_ids = set()
        self.pool_size = None
        self.pool_walkers = None
        self.wall0 = None
        self.last_t = None

    def _traffic(self, t, d):
        users = d.get("users", [])
        signals = d.get("signals", {})
        if d.get("pool_size") is not None:  # the pooled city: how many vehicles the pool drives
            self.pool_size = max(self.pool_size or 0, d["pool_size"])
            self.pool_walkers = max(self.pool_walkers or 0, d.get("pool_pedestrians") or 0)
        row = {"t": round(t, 3), "users": users, "signals": signals}
        line = json.dumps(row, separators=(",", ":"))
        self.tracks_file.write(line + "\n")
        self.digest.update(line.encode())
        for uid, cls, x, y, yaw, speed, length, loff in users:
            self._track(uid, cls, x, y)
            if uid.startswith("sumo/"):
                self.sumo_ids.add(uid)
            if cls == "pedestrian":
                continue
            # Red-light violations: the front crosses its approach's stop line on red and then
            # enters the junction (the end of its road) on red. Vehicles stop at the stop line
            # or, as SUMO's, at the junction's edge behind the crosswalk; both are legal, as is
            # a vehicle that crossed the line on yellow and enters on red.
            fx = x + (loff + 0.5 * length) * math.cos(yaw)
            fy = y + (loff + 0.5 * length) * math.sin(yaw)
            for sl in self.map.stop_lines:
                a = sl.ahead(fx, fy, yaw, at_entry=True)
                key = (uid, sl.id)
                prev = self.prev_ahead.get(key)
                if a is None:
                    self.prev_ahead.pop(key, None)
                    continue
                self.prev_ahead[key] = a
                line_key = (uid, sl.id, "line")
                b = sl.ahead(fx, fy, yaw)
                pb = self.prev_ahead.get(line_key)
                self.prev_ahead[line_key] = b
                if pb is not None and b is not None and pb > 0 >= b:
                    self.crossed_on_red[(uid, sl.id)] = signals.get(sl.id) == "red"
                if prev is not None and prev > 0 >= a and signals.get(sl.id) == "red" and \
                        self.crossed_on_red.get((uid, sl.id), True):
                    self.violations.append({"t": round(t, 3), "id": uid, "class": cls,
                                            "signal": sl.id, "speed_mps": round(speed, 2)})
        tgt = d.get("target")
        if tgt and tgt.get("ttc_s") is not None and not str(tgt.get("lead", "")).startswith("stop_line"):
            ttc = float(tgt["ttc_s"])
            if math.isfinite(ttc) and (self.min_ttc is None or ttc < self.min_ttc):
                self.min_ttc = ttc

    def _track(self, uid, cls, x, y):
        self.seen.add(uid)
        p = px(x, y)
        last = self.last_px.get(uid)
        if last is not None and max(abs(p[0] - last[0]), abs(p[1] - last[1])) < 2:
            return  # less than 1 m from the last point drawn (or a standing road user's jitter)
        self.last_px[uid] = p
        if uid == EGO:
            self.ego_px.append(p)
            return
        if self.tracks_img is None:
            self.tracks_img = self._background()
        # No line across a jump (a road user back in the pooled city's radius elsewhere).
        if last is not None and max(abs(p[0] - last[0]), abs(p[1] - last[1])) < 20 * SCALE:
            cv2.line(self.tracks_img, last, p, COLOURS.get(cls, (200, 200, 200)), 1, cv2.LINE_AA)

    def _frame(self, obs):
        frame = obs.get("frame")
        if frame is None:
            return
        key = hash(frame[::29, ::31].tobytes())
        if key == self.last_key:
            return
        self.last_key = key
        img = cv2.cvtColor(np.ascontiguousarray(frame[:, :, :3]), cv2.COLOR_RGB2BGR)
        for det in (obs.get("detections") or {}).get("detections", []):
            p1, p2 = (int(det["x_min"]), int(det["y_min"])), (int(det["x_max"]), int(det["y_max"]))
            cv2.rectangle(img, p1, p2, (0, 255, 255), 2)
            cv2.putText(img, det["class"], (p1[0], max(12, p1[1] - 4)), cv2.FONT_HERSHEY_SIMPLEX,
                        0.45, (0, 255, 255), 1, cv2.LINE_AA)
        if self.video is None:
            self.video = VideoWriter(os.path.join(self.dir, "camera.mp4"), FPS)
        self.video.write(img)
        self.frames += 1

    def runLoop(self, timestep_ns):
        if self.wall0 is None:
            self.wall0 = time.perf_counter()
            self.sim0 = self._time_ns - timestep_ns
        t = self._time_ns * 1e-9
        self.last_t = self._time_ns
        d = self._getDataPack("traffic")
        if d and d.get("users") is not None and d is not getattr(self, "_last_traffic", None):
            self._last_traffic = d
            self._traffic(t, d)
        obs = self._getDataPack("observation")
        if obs:
            self._frame(obs)
            dets = (obs.get("detections") or {}).get("detections")
            if dets is not None:
                k = json.dumps(dets, sort_keys=True)
                if k != self.last_det_key:
                    self.last_det_key = k
                    self.detector_frames += 1
                    self.detections += len(dets)
            if obs.get("collisions") is not None:
                self.collisions = obs["collisions"]
        if self._time_ns % 10_000_000_000 == 0:
            print("t=%5.1f s  road users %d  frames %d  collisions %d  red-light violations %d" % (
                t, len(self.seen), self.frames, len(self.collisions), len(self.violations)), flush=True)

    def _background(self):
        share = os.environ.get("CONVOY_SHARE_DIR", "")
        obj = os.path.join(share, "models", ROAD_MODEL, "road.obj")
        W, H = int((X1 - X0) * SCALE), int((Y1 - Y0) * SCALE)
        img = np.full((H, W, 3), (70, 110, 70), np.uint8)
        if os.path.exists(obj):
            v, faces = load_obj(obj)
            pts = np.stack([(v[:, 0] - X0) * SCALE, (Y1 - v[:, 1]) * SCALE], axis=1).astype(np.int32)
            for f in faces:
                cv2.fillConvexPoly(img, pts[f], (105, 105, 105))
        for sl in self.map.stop_lines:
            c, s = math.cos(sl.heading), math.sin(sl.heading)
            a = (sl.x - sl.t_min * s, sl.y + sl.t_min * c)
            b = (sl.x - sl.t_max * s, sl.y + sl.t_max * c)
            cv2.line(img, px(*a), px(*b), (255, 255, 255), 1)
        return img

    def _birds_eye(self):
        img = self.tracks_img if self.tracks_img is not None else self._background()
        if len(self.ego_px) > 1:
            cv2.polylines(img, [np.array(self.ego_px, np.int32)], False, (0, 255, 255), 3, cv2.LINE_AA)
        legend = [("ego", (0, 255, 255))] + [(k, c) for k, c in COLOURS.items()]
        for i, (name, col) in enumerate(legend):
            cv2.line(img, (10, 14 + 16 * i), (30, 14 + 16 * i), col, 3)
            cv2.putText(img, name, (36, 18 + 16 * i), cv2.FONT_HERSHEY_SIMPLEX, 0.45, (255, 255, 255), 1,
                        cv2.LINE_AA)
        cv2.imwrite(os.path.join(self.dir, "birds_eye.png"), img)

    def shutdown(self):
        if not hasattr(self, "tracks_file"):
            return
        self.tracks_file.close()
        if self.video is not None:
            self.video.close()
        self._birds_eye()
        wall = time.perf_counter() - self.wall0 if self.wall0 is not None else 0.0
        sim = (self.last_t - self.sim0) * 1e-9 if self.wall0 is not None else 0.0
        participants = {}
        try:
            with open(os.path.join(self.dir, "config.json")) as f:
                for e in json.load(f)["EngineConfigs"]:
                    participants[e["EngineType"]] = participants.get(e["EngineType"], 0) + 1
        except (OSError, ValueError, KeyError):
            pass
        participants["sumo_vehicles"] = len(self.sumo_ids)
        planner = {}
        try:
            with open(os.path.join(self.dir, "ego_planner.json")) as f:
                planner = json.load(f)
        except (OSError, ValueError):
            print("recorder: no ego_planner.json in the run folder", flush=True)
        summary = {
            "participants": participants,
            "collisions": [{k: c.get(k) for k in ("t", "a", "b", "class_a", "class_b",
                                                   "relative_speed_mps")} for c in self.collisions],
            "min_ttc_s": self.min_ttc,
            "red_light_violations": len(self.violations),
            "red_light_violation_list": self.violations,
            "ego_stops_for_pedestrians": planner.get("ego_stops_for_pedestrians"),
            "ego_input": planner.get("input_label"),
            "road_users_seen": len(self.seen),
            "pooled_vehicles": self.pool_size,
            "pooled_pedestrians": self.pool_walkers,
            "tracks_sha1": self.digest.hexdigest(),
            "camera_frames": self.frames,
            "camera_frames_per_s": self.frames / wall if wall > 0 else None,
            "detector_frames": self.detector_frames,
            "detections": self.detections,
            "detections_per_s": self.detections / wall if wall > 0 else None,
            "simulated_s": sim,
        }
        path = os.path.join(self.dir, "summary.json")
        try:  # keep what functions wrote there (score_tf.py's live score)
            with open(path) as f:
                summary = {**json.load(f), **summary}
        except (OSError, ValueError, TypeError):
            pass
        with open(path, "w") as f:
            json.dump(summary, f, indent=1)
        print("recorder: %d road users, %d collisions, %d red-light violations, min TTC %s, "
              "ego stops for pedestrians %s, %d camera frames; %s" % (
                  len(self.seen), len(self.collisions), len(self.violations), self.min_ttc,
                  summary["ego_stops_for_pedestrians"], self.frames, path), flush=True)
