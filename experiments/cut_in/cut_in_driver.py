"""A Python road user that cuts in aggressively (docs/road_users.md, "A Python road user").

Drives east on the city map's main road (road 1: a straight line from (-250, 0) heading +x,
right-hand traffic: lane -1 centre at y = -1.75, lane -2 at y = -5.25). It starts in lane -2,
finds the vehicle agent it is to cut in front of in its `neighbours` input, passes it, and once
its rear is just ahead of the agent's front (time gap below CUT_GAP_S) steers into lane -1,
with the left indicator on for INDICATOR_S only. It publishes its RoadUser as a JSON dict
under `state` each step. Deterministic: no randomness.
"""

import math

from nrp_core.engines.python_json import EngineScript

LANE_Y = {-1: -1.75, -2: -5.25}
LENGTH, WIDTH, HEIGHT, LENGTH_OFFSET = 4.5, 1.8, 1.5, 1.3
INDICATOR_LEFT = 4
CUT_GAP_S = 0.4      # cut in when the gap to the agent's front is below this time gap
INDICATOR_S = 0.5    # indicator on this long before and during the lane change
LANE_CHANGE_S = 1.5  # lateral move duration


class Script(EngineScript):
    def initialize(self):
        # The engine config may override these (extra keys: the coordinator warns that it does
        # not know them, and passes them on).
        cfg = self._config
        self.target = cfg.get("Target", "car_0")
        self.x = float(cfg.get("StartX", -235.0))
        self.speed = float(cfg.get("InitialSpeed", 13.0))
        self.cruise = float(cfg.get("CruiseSpeed", 14.0))
        self.y = LANE_Y[-2]
        self.lane = -2
        self.phase = "pass"  # pass -> signal -> change -> done
        self.t_phase = 0.0
        self.acc = 0.0
        self.yaw = 0.0
        self._registerDataPack("neighbours")
        self._registerDataPack("state")
        self._publish(0)

    def _target(self):
        nb = self._getDataPack("neighbours")
        users = nb.get("users", [nb]) if isinstance(nb, dict) else []
        for u in users:
            if u.get("id") == self.target:
                return u
        return None

    def runLoop(self, timestep_ns):
        dt = timestep_ns * 1e-9
        agent = self._target()
        lights = 0
        if self.phase == "pass" and agent is not None:
            front = agent["x"] + agent.get("length_offset", 0.0) + agent.get("length", 4.5) / 2
            my_rear = self.x + LENGTH_OFFSET - LENGTH / 2
            gap = my_rear - front
            if gap > 0 and gap < CUT_GAP_S * max(agent.get("speed", 0.0), 1.0):
                self.phase, self.t_phase = "signal", 0.0
        if self.phase in ("signal", "change"):
            self.t_phase += dt
            if self.t_phase <= INDICATOR_S + 0.001:
                lights |= INDICATOR_LEFT
        if self.phase == "signal" and self.t_phase >= INDICATOR_S:
            self.phase, self.t_phase = "change", 0.0
        vy = 0.0
        if self.phase == "change":
            f = min(self.t_phase / LANE_CHANGE_S, 1.0)
            y_new = LANE_Y[-2] + (LANE_Y[-1] - LANE_Y[-2]) * (0.5 - 0.5 * math.cos(math.pi * f))
            vy = (y_new - self.y) / dt
            self.y = y_new
            if f >= 0.5:
                self.lane = -1
            if f >= 1.0:
                self.phase = "done"
        self.acc = max(-3.0, min(2.0, (self.cruise - self.speed)))
        self.speed = max(0.0, self.speed + self.acc * dt)
        self.x += self.speed * dt
        self.yaw = math.atan2(vy, self.speed) if self.speed > 0 else 0.0
        self._publish(lights)

    def _publish(self, lights):
        self._setDataPack("state", {
            "id": self._name, "category": "car", "model": "sedan",
            "x": self.x, "y": self.y, "z": 0.0, "yaw": self.yaw,
            "speed": self.speed, "acceleration": self.acc,
            "vx": self.speed * math.cos(self.yaw), "vy": self.speed * math.sin(self.yaw),
            "length": LENGTH, "width": WIDTH, "height": HEIGHT,
            "length_offset": LENGTH_OFFSET, "lights": lights,
            "road": "1", "lane": self.lane, "s": self.x + 250.0, "t": self.y,
            "time_ns": self._time_ns})
