"""A python_json road user: a pedestrian who steps out in front of the ego.

It waits on the right-hand kerb of the ego's lane (the Parkring's first straight: lane -1
centred at y = -1.7, heading +x) at x = PED_X, and steps out when the ego's front is
TRIGGER_M ahead of it, walking at WALK_SPEED across the lane to its centre line, where it
stays. It reads the ego's RoadUser (`ego`, forwarded by a TF) and publishes its own as JSON
under `state` (docs/road_users.md). Deterministic."""
import json
import math
import os

from nrp_core.engines.python_json import EngineScript

PED_X = 90.0
KERB_Y = -4.0        # m: waiting here
STOP_Y = -1.7        # m: walks to the lane's centre line and stays
TRIGGER_M = 30.0     # m: steps out when the ego's front is this far away
WALK_SPEED = 1.5     # m/s
STRIDE = 1.4         # m walked per walking cycle (its walk_phase 0 -> 1)


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
        self.y = KERB_Y
        self.phase = "wait"
        self.t_step = None
        self.rec = {"ground_truth": True, "step_out_time_s": None, "ego_gap_at_step_out_m": None,
                    "ego_speed_at_step_out_mps": None, "min_gap_m": None, "ego_final_speed_mps": None,
                    "collisions": []}
        self._registerDataPack("ego")
        self._registerDataPack("collisions")
        self._registerDataPack("state")
        self._publish(0.0)

    def runLoop(self, timestep_ns):
        dt = timestep_ns * 1e-9
        ego = self._getDataPack("ego") or {}
        vy = 0.0
        if self.phase == "wait" and "x" in ego:
            front = ego["x"] + ego.get("length_offset", 0.0) + ego.get("length", 0.0) / 2
            if PED_X - 0.25 - front <= TRIGGER_M:
                self.phase, self.t_step = "walk", self._time_ns * 1e-9
                self.rec.update(step_out_time_s=self.t_step, ego_gap_at_step_out_m=PED_X - 0.25 - front,
                                ego_speed_at_step_out_mps=ego.get("speed", 0.0))
                print("pedestrian steps out at t=%.2f s, ego front %.2f m away at %.2f m/s" % (
                    self.t_step, PED_X - 0.25 - front, ego.get("speed", 0.0)), flush=True)
        if self.phase == "walk":
            vy = WALK_SPEED
            self.y = min(self.y + vy * dt, STOP_Y)
            if self.y >= STOP_Y:
                self.phase, vy = "stand", 0.0
        self._publish(vy)
        if "x" in ego:
            g = _gap_ahead(ego, PED_X, self.y, 0.5, 0.5)
            if g is not None and (self.rec["min_gap_m"] is None or g < self.rec["min_gap_m"]):
                self.rec["min_gap_m"] = g
            self.rec["ego_final_speed_mps"] = ego.get("speed", 0.0)
        col = self._getDataPack("collisions")
        if col and col.get("list"):
            self.rec["collisions"] = col["list"]

    def shutdown(self):
        write_record("pedestrian.json", self.rec)

    def _publish(self, vy):
        self._setDataPack("state", {
            "id": "pedestrian", "category": "pedestrian", "model": "pedestrian",
            "x": PED_X, "y": self.y, "z": 0.0, "yaw": math.pi / 2 if vy > 0 else 0.0,
            "speed": vy, "vx": 0.0, "vy": vy, "length": 0.5, "width": 0.5, "height": 1.75,
            "walk_phase": ((self.y - KERB_Y) / STRIDE) % 1.0, "time_ns": self._time_ns})
