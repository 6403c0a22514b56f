"""Engine 1: its datapack "datapack1" holds its simulated time in ms."""
from nrp_core.engines.python_json import EngineScript


class Script(EngineScript):
    def initialize(self):
        self._registerDataPack("datapack1")
        self._setDataPack("datapack1", {"time_ms": 0})

    def runLoop(self, timestep_ns):
        self._setDataPack("datapack1", {"time_ms": self._time_ns // 1000000})

    def shutdown(self):
        print("Engine 1 is shutting down")
