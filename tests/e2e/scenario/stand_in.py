"""A kinematic road user for the scenario engine's end-to-end tests (tests/e2e/test_scenario.py):
a python_json engine that obeys the scenario engine's commands as the contract of
vehicle_agent / pedestrian_agent's CommandDataPack says (docs/scenarios.md), on a straight
road along +x (tests/unit/scenarios/straight.xodr: lanes 3.5 m wide, lane -1 centred at
y = -1.75), and otherwise keeps its speed and lane ("its own AI").

Config keys: Start {"x", "y", "yaw", "speed"}, Category, Length, Width, CommandDataPack.
Writes every step to $CONVOY_RUN_DIR/<name>.jsonl: t, x, y, yaw, speed and the command's keys."""
import json
import math
import os

from nrp_core.engines.python_json import EngineScript

LANE_W = 3.5


def lane_centre(lane):
    lane = int(lane)
    return -(abs(lane) - 0.5) * LANE_W if lane < 0 else (lane - 0.5) * LANE_W


def lane_of(y):
    k = int(abs(y) // LANE_W) + 1
    return -k if y < 0 else k


class Script(EngineScript):
    def initialize(self):
        c = self._config
        s = c["Start"]
        self.x, self.y, self.yaw, self.speed = s["x"], s["y"], s.get("yaw", 0.0), s.get("speed", 0.0)
        self.cmd_dp = c.get("CommandDataPack", "command")
        self._registerDataPack("state")
        self._registerDataPack(self.cmd_dp)
        self.log = open(os.path.join(os.environ["CONVOY_RUN_DIR"], self._name + ".jsonl"), "w")
        self.polyline = None
        self._publish()

    def _publish(self):
        self._setDataPack("state", {
            "id": self._name, "category": self._config.get("Category", "car"), "x": self.x, "y": self.y,
            "yaw": self.yaw, "speed": self.speed, "vx": self.speed * math.cos(self.yaw),
            "vy": self.speed * math.sin(self.yaw), "length": self._config.get("Length", 4.5),
            "width": self._config.get("Width", 1.8), "length_offset": 1.4, "road": "1",
            "lane": lane_of(self.y), "s": self.x, "t": self.y, "time_ns": self._time_ns})

    def _along(self, pts, dist):
        """Moves dist along the polyline pts from the nearest point ahead."""
        best, bi = None, 0
        for i in range(len(pts) - 1):
            (ax, ay), (bx, by) = pts[i], pts[i + 1]
            dx, dy = bx - ax, by - ay
            n2 = dx * dx + dy * dy or 1e-12
            u = max(0.0, min(1.0, ((self.x - ax) * dx + (self.y - ay) * dy) / n2))
            d = math.hypot(ax + u * dx - self.x, ay + u * dy - self.y)
            if best is None or d < best:
                best, bi, bu = d, i, u
        i, u = bi, bu
        while dist > 0 and i < len(pts) - 1:
            (ax, ay), (bx, by) = pts[i], pts[i + 1]
            seg = math.hypot(bx - ax, by - ay)
            left = (1 - u) * seg
            if dist < left:
                u += dist / seg
                dist = 0
            else:
                dist -= left
                i, u = i + 1, 0.0
        i = min(i, len(pts) - 2)
        (ax, ay), (bx, by) = pts[i], pts[i + 1]
        self.x, self.y = ax + u * (bx - ax), ay + u * (by - ay)
        self.yaw = math.atan2(by - ay, bx - ax)

    def runLoop(self, timestep_ns):
        dt = timestep_ns * 1e-9
        cmd = self._getDataPack(self.cmd_dp) or {}
        if "teleport" in cmd:
            tp = cmd["teleport"]
            self.x, self.y, self.yaw = tp["x"], tp["y"], tp["yaw"]
            self.speed = tp.get("speed", self.speed)
        if "speed" in cmd:
            self.speed = cmd["speed"]["speed"]
        tr = cmd.get("trajectory")
        if tr is not None and "x" in tr:
            self.x, self.y, self.yaw, self.speed = tr["x"], tr["y"], tr["yaw"], tr["speed"]
        elif tr is not None or "route" in cmd:
            pts = tr["polyline"] if tr is not None else cmd["route"]["positions"]
            (ax, ay), (bx, by) = pts[0], pts[1]
            if (self.x - ax) * (bx - ax) + (self.y - ay) * (by - ay) < 0:  # before the first point
                pts = [[self.x, self.y]] + pts
            self._along(pts, self.speed * dt)
        else:
            self.x += self.speed * math.cos(self.yaw) * dt
            self.y += self.speed * math.sin(self.yaw) * dt
            if "lane" in cmd:
                ln = cmd["lane"]
                p = ln["progress"]
                self.y = (1 - p) * lane_centre(ln["from_lane"]) + p * lane_centre(ln["lane"]) + p * ln.get("offset", 0.0)
        self._publish()
        self.log.write(json.dumps({"t": round(self._time_ns * 1e-9, 4), "x": self.x, "y": self.y, "yaw": self.yaw,
                                   "speed": self.speed, "cmd": sorted(k for k in cmd if k != "time_ns")}) + "\n")

    def shutdown(self):
        self.log.close()
