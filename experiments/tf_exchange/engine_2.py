"""Python engine 2: receives what tf_1 relays from engine 1 and logs it."""
from nrp_core.engines.python_json import EngineScript


class Script(EngineScript):
    def initialize(self):
        print("Engine 2 is initializing. Registering datapack...")
        self._registerDataPack("rec_datapack2")
        self._setDataPack("rec_datapack2", {"time": 0, "timestep": 0})
        self.received = 0

    def runLoop(self, timestep_ns):
        received = self._getDataPack("rec_datapack2")
        self.received += 1
        print("Engine 2 at time %d ns received: %s" % (self._time_ns, received))

    def shutdown(self):
        print("Engine 2 is shutting down after %d steps" % self.received)
