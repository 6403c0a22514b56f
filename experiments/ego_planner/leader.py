"""A python_json road user: a slower car ahead of the ego on the Parkring's driving lane.

It starts START_AHEAD m along the lane's waypoints (the ones the report's follower uses) and
drives along them at SPEED, publishing its RoadUser as JSON under `state`
(docs/road_users.md). Deterministic."""
import json
import math
import os
import sys

from nrp_core.engines.python_json import EngineScript

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "autonomous_driving"))
import relateAngle_computation  # noqa: E402  the report's waypoints

START_AHEAD = 30.0  # m along the lane from the ego's start
SPEED = 4.0         # m/s
LENGTH, WIDTH, HEIGHT = 4.5, 1.8, 1.5


def _gap_ahead(ego, x, y, length, width):
    """Ground truth: the ego's front to the road user's near edge along the ego's axis, if the
    road user overlaps the ego's width laterally (else None)."""
    c, s = math.cos(ego["yaw"]), math.sin(ego["yaw"])
    dx, dy = x - ego["x"], y - ego["y"]
    lon, lat = c * dx + s * dy, -s * dx + c * dy
    if abs(lat) > (ego.get("width", 1.8) + width) / 2:
        return None
    return lon - length / 2 - (ego.get("length_offset", 0.0) + ego.get("length", 0.0) / 2)


def write_record(name, rec):
    run_dir = os.environ.get("CONVOY_RUN_DIR", ".")
    with open(os.path.join(run_dir, name), "w") as f:
        json.dump(rec, f, indent=1, sort_keys=True)


class Script(EngineScript):
    def initialize(self):
        pts = relateAngle_computation.load_waypoints()
        self.pts, self.cum = pts, [0.0]
        for a, b in zip(pts, pts[1:]):
            self.cum.append(self.cum[-1] + math.hypot(b[0] - a[0], b[1] - a[1]))
        self.s = START_AHEAD
        self.i = 0
        self.rec = {"ground_truth": True, "leader_speed_mps": SPEED, "min_gap_m": None,
                    "trace": [], "collisions": []}
        self._registerDataPack("ego")
        self._registerDataPack("collisions")
        self._registerDataPack("state")
        self._publish()

    def _pose(self):
        while self.i + 2 < len(self.cum) and self.cum[self.i + 1] < self.s:
            self.i += 1
        (x0, y0), (x1, y1) = self.pts[self.i], self.pts[self.i + 1]
        seg = max(self.cum[self.i + 1] - self.cum[self.i], 1e-9)
        f = (self.s - self.cum[self.i]) / seg
        return x0 + f * (x1 - x0), y0 + f * (y1 - y0), math.atan2(y1 - y0, x1 - x0)

    def runLoop(self, timestep_ns):
        self.s += SPEED * timestep_ns * 1e-9
        self._publish()
        ego = self._getDataPack("ego") or {}
        if "x" in ego:
            x, y, _ = self._pose()
            g = _gap_ahead(ego, x, y, LENGTH, WIDTH)
            if g is not None and (self.rec["min_gap_m"] is None or g < self.rec["min_gap_m"]):
                self.rec["min_gap_m"] = g
            if self._time_ns % 500_000_000 == 0:
                self.rec["trace"].append({"t": round(self._time_ns * 1e-9, 2),
                                          "ego_speed_mps": ego.get("speed", 0.0),
                                          "gap_m": None if g is None else round(g, 3)})
        col = self._getDataPack("collisions")
        if col and col.get("list"):
            self.rec["collisions"] = col["list"]

    def shutdown(self):
        write_record("leader.json", self.rec)

    def _publish(self):
        x, y, yaw = self._pose()
        self._setDataPack("state", {
            "id": "leader", "category": "car", "model": "sedan",
            "x": x, "y": y, "z": 0.0, "yaw": yaw, "speed": SPEED,
            "vx": SPEED * math.cos(yaw), "vy": SPEED * math.sin(yaw),
            "length": LENGTH, "width": WIDTH, "height": HEIGHT, "length_offset": 0.0,
            "time_ns": self._time_ns})
