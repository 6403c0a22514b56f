"""End-to-end tests of GazeboSDFModels' InitSpeed (engines/gazebo_grpc/systems/initial_speeds.h):
the report's smart car inserted at 10 m/s on a flat world rolls on with no command; a
negative or non-numeric InitSpeed is a config error naming the engine config's entry.

Run with Debian's /usr/bin/python3 -m unittest test_world_init_speed."""

import json
import math
import os
import textwrap
import unittest

from test_core import Experiment

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
MODELS = os.path.join(REPO, "experiments", "city_traffic", "models")
CAR = os.path.join(MODELS, "smart_car", "model.sdf")
YAW = 0.5

FLAT_WORLD = """<?xml version="1.0"?>
<sdf version="1.7">
  <world name="flat">
    <physics type="ode"><max_step_size>0.001</max_step_size></physics>
    <model name="ground">
      <static>true</static>
      <link name="link">
        <collision name="c"><geometry><plane><normal>0 0 1</normal><size>500 500</size></plane></geometry></collision>
      </link>
    </model>
  </world>
</sdf>
"""

PROBE = textwrap.dedent("""\
    import json, os
    from nrp_core.engines.python_json import EngineScript
    class Script(EngineScript):
        def initialize(self):
            self._registerDataPack("car")
            self.log = []
        def runLoop(self, timestep_ns):
            self.log.append(self._getDataPack("car"))
        def shutdown(self):
            with open(os.path.join(os.path.dirname(__file__), "car.json"), "w") as f:
                json.dump(self.log, f)
    """)

TF = textwrap.dedent("""\
    from nrp_core import *
    from nrp_core.data.nrp_json import *
    @EngineDataPack(keyword='car', id=DataPackIdentifier('smart_car::road_user', 'gazebo'))
    @TransceiverFunction("probe")
    def tf(car):
        if car.isEmpty():
            return []
        d = car.data
        return [JsonDataPack("car", "probe", {"t": d.time_ns * 1e-9, "speed": d.speed,
                                              "x": d.x, "y": d.y})]
    """)


class InitSpeed(unittest.TestCase):
    def experiment(self, speed):
        ex = Experiment(self)
        ex.file("world.sdf", FLAT_WORLD)
        ex.engines.append({"EngineType": "gazebo_grpc", "EngineName": "gazebo",
                           "GazeboWorldFile": "world.sdf", "EngineTimestep": 0.02,
                           "EngineEnvParams": ["CONVOY_MODEL_PATH=" + MODELS],
                           "GazeboSDFModels": [{"Name": "smart_car", "File": CAR,
                                                "InitPose": [0, 0, 0, 0, 0, YAW],
                                                "InitSpeed": speed}]})
        return ex

    def test_the_smart_car_rolls_on_at_its_init_speed(self):
        ex = self.experiment(10)
        ex.engine("probe", PROBE, timestep=0.02)
        ex.function("tf", TF)
        ex.run(2.0)
        with open(os.path.join(ex.dir, "car.json")) as f:
            seen = [s for s in json.load(f) if s]
        first = seen[0]
        at = {round(s["t"], 2): s for s in seen}
        half, end = at[0.5], seen[-1]
        print("smart car, InitSpeed 10, no command: %.3f m/s after 0.5 s, %.3f m/s after %.2f s"
              % (half["speed"], end["speed"], end["t"]))
        self.assertAlmostEqual(first["speed"], 10.0, delta=0.2)
        self.assertAlmostEqual(half["speed"], 10.0, delta=0.2)
        self.assertAlmostEqual(end["speed"], 10.0, delta=0.3)
        # about 5 m along the heading in 0.5 s (from the first report, one step in)
        dx, dy = half["x"] - first["x"], half["y"] - first["y"]
        along = dx * math.cos(YAW) + dy * math.sin(YAW)
        across = -dx * math.sin(YAW) + dy * math.cos(YAW)
        self.assertAlmostEqual(along, 10.0 * (half["t"] - first["t"]), delta=0.15)
        self.assertAlmostEqual(across, 0.0, delta=0.05)

    def test_a_negative_or_non_numeric_init_speed_is_a_config_error(self):
        for bad in (-1, "fast"):
            with self.subTest(InitSpeed=bad):
                r = self.experiment(bad).run(0.1, expect=2)
                self.assertIn("/EngineConfigs/0/GazeboSDFModels/0/InitSpeed", r.stderr)
                self.assertIn("simulation_config.json", r.stderr)


if __name__ == "__main__":
    unittest.main()
