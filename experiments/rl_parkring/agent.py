"""The agent's engine: holds the action the Python client sets (set_json_datapack("action",
"agent", {"steer": rad, "speed": m/s})) until the next one; drive_tf reads it every step."""
from nrp_core.engines.python_json import EngineScript

STOP = {"steer": 0.0, "speed": 0.0}


class Script(EngineScript):
    def initialize(self):
        self._registerDataPack("action")
        self._setDataPack("action", dict(STOP))

    def runLoop(self, timestep_ns):
        pass

    def reset(self):
        self._setDataPack("action", dict(STOP))
