import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "dataplane"))
from steptimer import StepTimer  # noqa: E402

from nrp_core.engines.python_json import EngineScript  # noqa: E402


class Script(EngineScript):
    def initialize(self):
        self.timer = StepTimer(self._name, os.path.dirname(os.path.abspath(__file__)))
        self._registerDataPack("frame")
        self.frames = 0
        self.changed = 0
        self.last = None

    def runLoop(self, timestep_ns):
        self.timer.tick()
        f = self._getDataPack("frame")
        if f is not None:
            self.frames += 1
            key = (f["mean"], f["first"])
            self.changed += key != self.last
            self.last = key

    def shutdown(self):
        self.timer.dump(frames=self.frames, changed=self.changed)
