"""Engine 2: prints what the graph sent it, once a simulated second."""
from nrp_core.engines.python_json import EngineScript


class Script(EngineScript):
    def initialize(self):
        self._registerDataPack("rec_datapack2")

    def runLoop(self, timestep_ns):
        if self._time_ns % 1000000000 == 0:
            print("Engine 2 at %d ms received %s" % (self._time_ns // 1000000,
                                                      self._getDataPack("rec_datapack2")),
                  flush=True)

    def shutdown(self):
        print("Engine 2 is shutting down")
