"""Saves the ego camera's frames at given simulated times as PNG files in the run folder
(camera_<t>s.png): a python_json engine that make_config.py --snapshots T1,T2 adds with
snapshot_tf.py (docs/scenarios.md, "Pictures"). Times from $CONVOY_SNAPSHOT_TIMES (seconds,
comma-separated)."""
import os

import cv2
import numpy as np
from nrp_core.engines.python_json import EngineScript


class Script(EngineScript):
    def initialize(self):
        self._registerDataPack("frame")
        self.times = sorted(float(t) for t in os.environ.get("CONVOY_SNAPSHOT_TIMES", "").split(",") if t)
        self.dir = os.environ.get("CONVOY_RUN_DIR", ".")

    def runLoop(self, timestep_ns):
        t = self._time_ns * 1e-9
        if not self.times or t + 1e-9 < self.times[0]:
            return
        frame = self._getDataPack("frame")
        if frame is None or not isinstance(frame, dict) or "image" not in frame:
            return
        img = np.asarray(frame["image"])
        path = os.path.join(self.dir, "camera_%gs.png" % self.times.pop(0))
        cv2.imwrite(path, cv2.cvtColor(np.ascontiguousarray(img[:, :, :3]), cv2.COLOR_RGB2BGR))
        print("snapshot: %s at t=%.2f" % (path, t), flush=True)
