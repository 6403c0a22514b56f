"""Vehicle control engine (report section 3.4.2): follows the pre-defined trajectory under
PID control of the steering (position) and rear wheels (velocity) in the world engine."""
import json
import math
import os

from nrp_core.engines.python_json import EngineScript

import relateAngle_computation
from euler_from_quaternion import euler_from_quaternion

WHEEL_RADIUS = 0.3   # m
MAX_STEER = 0.55     # rad
STEER_GAIN = 1.2


class Script(EngineScript):
    def initialize(self):
        self._registerDataPack("actors")  
        self._setDataPack("actors", {"angular_L": 0, "angular_R": 0, "linear_L": 0, "linear_R": 0})  
        self._registerDataPack("state_location")  
        self._setDataPack("state_location", { "location_x": 0, "location_y": 0, "qtn_x": 0, "qtn_y": 0,"qtn_z": 0,"qtn_w": 0})
        self.trajectory = relateAngle_computation.Trajectory()
        self.lap_time_s = None
        self.run_dir = os.environ.get("CONVOY_RUN_DIR", ".")
        self.log = open(os.path.join(self.run_dir, "trajectory.csv"), "w")
        self.log.write("time_s,x,y,yaw,target_index,steer\n")

    def runLoop(self, timestep_ns):
        state = self._getDataPack("state_location") 
        x, y = state["location_x"], state["location_y"]
        if state["qtn_w"] == 0 and state["qtn_z"] == 0:
            yaw = 0.0  # no pose received yet
        else:
            _, _, yaw = euler_from_quaternion(state["qtn_x"], state["qtn_y"], state["qtn_z"], state["qtn_w"])
        rel, _ = self.trajectory.update(x, y, yaw)
        steer = max(-MAX_STEER, min(MAX_STEER, STEER_GAIN * rel))
        speed = 0.0 if self.trajectory.finished else relateAngle_computation.SPEED
        if self.trajectory.finished and self.lap_time_s is None:
            self.lap_time_s = self._time_ns * 1e-9
            print("lap completed in %.1f s" % self.lap_time_s, flush=True)
        steerL_angle = steer
        steerR_angle = steer
        rearL_omiga = speed / WHEEL_RADIUS
        rearR_omiga = speed / WHEEL_RADIUS
        self._setDataPack("actors", {"angular_L": steerL_angle, "angular_R": steerR_angle, "linear_L": rearL_omiga, "linear_R": rearR_omiga}) 
        t = self._time_ns * 1e-9
        self.log.write("%.3f,%.4f,%.4f,%.5f,%d,%.4f\n" % (t, x, y, yaw, self.trajectory.index, steer))
        if self._time_ns % 5_000_000_000 == 0:
            print("t=%6.1f s  x=%8.2f y=%8.2f  waypoint %d/%d" % (
                t, x, y, self.trajectory.index, len(self.trajectory.points)), flush=True)

    def shutdown(self):
        self.log.close()
        with open(os.path.join(self.run_dir, "control_summary.json"), "w") as f:
            json.dump({"lap_completed": self.lap_time_s is not None, "lap_time_s": self.lap_time_s,
                       "waypoints_reached": self.trajectory.index - 1,
                       "waypoints": len(self.trajectory.points)}, f, indent=1)
