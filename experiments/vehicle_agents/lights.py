"""A fixed-time program for the city map's lights (junctions 100 and 200): main road green
20 s, yellow 3 s, then the side road the same; a python_json engine publishing the
traffic_lights layout the vehicle agents read ({"time_ns", "signals": {id: state}})."""

from nrp_core.engines.python_json import EngineScript

MAIN = {"100": ["1", "2"], "200": ["5", "6"]}
SIDE = {"100": ["3", "4"], "200": ["7", "8"]}
GREEN, YELLOW = 20.0, 3.0


class Script(EngineScript):
    def initialize(self):
        self._registerDataPack("traffic_lights")
        self._publish()

    def runLoop(self, timestep_ns):
        self._publish()

    def _publish(self):
        t = (self._time_ns * 1e-9) % (2 * (GREEN + YELLOW))
        main = "green" if t < GREEN else "yellow" if t < GREEN + YELLOW else "red"
        u = t - (GREEN + YELLOW)
        side = "red" if u < 0 else "green" if u < GREEN else "yellow"
        signals = {}
        for ids in MAIN.values():
            signals.update({i: main for i in ids})
        for ids in SIDE.values():
            signals.update({i: side for i in ids})
        self._setDataPack("traffic_lights", {"time_ns": self._time_ns, "signals": signals})
