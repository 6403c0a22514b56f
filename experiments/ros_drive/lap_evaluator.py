"""Lap evaluator engine: scores the drive into the run folder ($CONVOY_RUN_DIR).

  trajectory.csv  time_s, x, y, yaw, speed, target_index per step (full precision: two runs of
                  the same experiment must give the same file byte for byte)
  summary.json    lap_completed and lap_time_s (the lap by the autonomous_driving
                  experiment's rule: every waypoint of the lane reached within 0.8 m or
                  passed, back to the start), waypoints_reached, distance_m, the
                  cross-track error to the lane (mean, max) and the physics real-time factor
                  (the coordinator adds its own fields at the end)
Progress goes to the log every simulated 5 s."""
import json
import math
import os
import sys
import time

from nrp_core.engines.python_json import EngineScript

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..",
                                "autonomous_driving"))
import relateAngle_computation  # noqa: E402


def yaw_of(rot):
    x, y, z, w = rot
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


def distance_to_lane(x, y, lane):
    best = float("inf")
    for i in range(len(lane)):
        (ax, ay), (bx, by) = lane[i], lane[(i + 1) % len(lane)]
        dx, dy = bx - ax, by - ay
        t = max(0.0, min(1.0, ((x - ax) * dx + (y - ay) * dy) / (dx * dx + dy * dy)))
        best = min(best, math.hypot(x - ax - t * dx, y - ay - t * dy))
    return best


class Script(EngineScript):
    def initialize(self):
        self._registerDataPack("pose")
        self.dir = os.environ.get("CONVOY_RUN_DIR", ".")
        self.trajectory = relateAngle_computation.Trajectory()
        self.lap_time_s = None
        self.path = []
        self.distance = 0.0
        self.wall0 = None
        self.log = open(os.path.join(self.dir, "trajectory.csv"), "w")
        self.log.write("time_s,x,y,yaw,speed,target_index\n")

    def runLoop(self, timestep_ns):
        if self.wall0 is None:
            self.wall0, self.sim0 = time.perf_counter(), self._time_ns - timestep_ns
        pose = self._getDataPack("pose")
        if not pose:
            return
        x, y, yaw = pose["x"], pose["y"], yaw_of(pose["rot"])
        speed = math.hypot(pose["lin_vel"][0], pose["lin_vel"][1])
        if self.path:
            self.distance += math.hypot(x - self.path[-1][0], y - self.path[-1][1])
        self.path.append((x, y))
        self.trajectory.update(x, y, yaw)
        t = self._time_ns * 1e-9
        if self.trajectory.finished and self.lap_time_s is None:
            self.lap_time_s = t
            print("lap completed in %.2f s" % t, flush=True)
        self.log.write("%r,%r,%r,%r,%r,%d\n" % (t, x, y, yaw, speed, self.trajectory.index))
        if self._time_ns % 5_000_000_000 == 0:
            print("t=%6.1f s  x=%8.2f y=%8.2f  %.1f m/s  waypoint %d/%d" % (
                t, x, y, speed, self.trajectory.index, len(self.trajectory.points)), flush=True)

    def shutdown(self):
        self.log.close()
        lane = self.trajectory.points
        errors = [distance_to_lane(x, y, lane) for x, y in self.path[::5]]
        wall = time.perf_counter() - self.wall0 if self.wall0 is not None else 0.0
        sim = (self._time_ns - self.sim0) * 1e-9 if self.wall0 is not None else 0.0
        summary = {
            "lap_completed": self.lap_time_s is not None,
            "lap_time_s": self.lap_time_s,
            "waypoints_reached": min(self.trajectory.index - 1, len(lane)),
            "waypoints": len(lane),
            "distance_m": self.distance,
            "cross_track_error_m": {"mean": sum(errors) / len(errors) if errors else None,
                                    "max": max(errors) if errors else None},
            "physics_real_time_factor": sim / wall if wall > 0 else None,
        }
        with open(os.path.join(self.dir, "summary.json"), "w") as f:
            json.dump(summary, f, indent=1)
        print("outputs: %s, %s" % (os.path.join(self.dir, "trajectory.csv"),
                                   os.path.join(self.dir, "summary.json")), flush=True)
