"""Logs the robot's trajectory to trajectory.csv in the run folder ($CONVOY_RUN_DIR) and
prints progress once per simulated second."""
import os

from nrp_core.engines.python_json import EngineScript


class Script(EngineScript):
    def initialize(self):
        self._registerDataPack("pose")
        path = os.path.join(os.environ.get("CONVOY_RUN_DIR", "."), "trajectory.csv")
        self.out = open(path, "w")
        self.out.write("time_s,x,y,speed\n")

    def runLoop(self, timestep_ns):
        pose = self._getDataPack("pose")
        if pose is None:
            return
        t = self._time_ns * 1e-9
        self.out.write("%.3f,%.6f,%.6f,%.6f\n" % (t, pose["x"], pose["y"], pose["speed"]))
        if self._time_ns % 1_000_000_000 == 0:
            print("t=%4.1f s  x=%6.2f  y=%6.2f  speed=%.2f m/s" % (t, pose["x"], pose["y"], pose["speed"]),
                  flush=True)

    def shutdown(self):
        self.out.close()
