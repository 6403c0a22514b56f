"""weather_braking's driver (a python_json engine): on each road surface the weather engine's
schedule brings, it drives the smart car up to 50 km/h on the straight road, brakes fully
(all four wheels, ABS) and measures the distance to standstill. It writes braking.json into
the run folder once every surface is done:

  {"speed_kmh": 50, "g": 9.81, "surfaces": {"dry": {"mu", "distance_m", "expected_m",
   "error", "start_speed_kmh", "stop_time_s", "brake_time_s"}, "wet": ..., ...}}

expected_m = v^2 / (2 mu g) at 50 km/h; error = distance_m / expected_m - 1. The distance
runs from the step the driver commands the brakes, so it includes one control step (5 ms)
of the loop's latency.

Datapacks: reads "state" ({x, y, vx, vy, surface, mu, time_s} from observe_tf.py); writes
"command" ({wheel_velocity (rad/s, rear wheels' PID target), brake (Nm per wheel)}).
"""
import json
import math
import os

from nrp_core.engines.python_json import EngineScript

SPEED_KMH = 50.0
TARGET = SPEED_KMH / 3.6  # m/s
WHEEL_RADIUS = 0.3  # m
BRAKE_TORQUE = 1500.0  # Nm per wheel: the brakes' MaxTorque, beyond any surface's grip
G = 9.81
SURFACES = ("dry", "wet", "snow", "ice")


class Script(EngineScript):
    def initialize(self):
        self._registerDataPack("command")
        self._setDataPack("command", {"wheel_velocity": 0.0, "brake": 0.0})
        self._registerDataPack("state")
        self._setDataPack("state", {})
        self.surface = None
        self.phase = "idle"
        self.results = {}
        self.start = None
        self.still_steps = 0
        self.run_dir = os.environ.get("CONVOY_RUN_DIR", ".")
        self.written = False

    def runLoop(self, timestep_ns):
        st = self._getDataPack("state")
        if not st or "surface" not in st:
            return
        t = self._time_ns * 1e-9
        speed = math.hypot(st["vx"], st["vy"])
        if st["surface"] != self.surface:
            self.surface = st["surface"]
            known = self.surface in SURFACES and self.surface not in self.results
            self.phase = "accelerate" if known else "idle"
            self.still_steps = 0
        wheel, brake = 0.0, BRAKE_TORQUE
        if self.phase == "accelerate":
            # The rear wheels' velocity PID aims 1 % above 50 km/h; the brakes go on as the car
            # passes 50 km/h.
            wheel, brake = 1.01 * TARGET / WHEEL_RADIUS, 0.0
            if speed >= TARGET:
                self.phase = "brake"
                self.start = {"x": st["x"], "y": st["y"], "t": t, "v": speed, "mu": st["mu"]}
                wheel, brake = 0.0, BRAKE_TORQUE
        elif self.phase == "brake":
            self.still_steps = self.still_steps + 1 if speed < 0.01 else 0
            if self.still_steps >= 3:
                self.record(st, t)
                self.phase = "done"
        self._setDataPack("command", {"wheel_velocity": wheel, "brake": brake})

    def record(self, st, t):
        s = self.start
        distance = math.hypot(st["x"] - s["x"], st["y"] - s["y"])
        expected = TARGET ** 2 / (2 * s["mu"] * G)
        self.results[self.surface] = {
            "mu": s["mu"],
            "distance_m": round(distance, 3),
            "expected_m": round(expected, 3),
            "error": round(distance / expected - 1, 4),
            "start_speed_kmh": round(s["v"] * 3.6, 3),
            "brake_time_s": round(s["t"], 3),
            "stop_time_s": round(t - s["t"], 3),
        }
        print("braking on %s (mu %.2f): %.2f m from %.2f km/h, v^2/(2 mu g) = %.2f m (%+.1f %%)"
              % (self.surface, s["mu"], distance, s["v"] * 3.6, expected,
                 100 * (distance / expected - 1)), flush=True)
        self.write()

    def write(self):
        out = {"speed_kmh": SPEED_KMH, "g": G,
               "surfaces": {k: self.results[k] for k in SURFACES if k in self.results}}
        with open(os.path.join(self.run_dir, "braking.json"), "w") as f:
            json.dump(out, f, indent=1)

    def shutdown(self):
        missing = [k for k in SURFACES if k not in self.results]
        if missing:
            print("weather_braking: no braking measured on %s (the run ended first)"
                  % ", ".join(missing), flush=True)
