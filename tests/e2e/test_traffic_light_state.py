"""End-to-end tests of traffic lights that show their state in the world engine's cameras
(engines/gazebo_grpc/systems/traffic_light_state.h): a camera looks at a traffic light and a
pedestrian light (tests/world/data/traffic_light_world.sdf) while their state changes, sent
by a python_json engine or by the traffic_lights engine, and a TF records the colour of each
lamp in the image.

Run with Debian's /usr/bin/python3 -m unittest test_traffic_light_state.
Set CONVOY_TRAFFIC_LIGHT_FRAMES=DIR to keep one frame of each state there as PNG."""

import json
import math
import os
import shutil
import textwrap
import unittest

from test_core import Experiment

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
WORLD = os.path.join(HERE, "..", "world", "data", "traffic_light_world.sdf")
CITY = os.path.join(REPO, "experiments", "city_traffic", "city.xodr")

# The rig's camera: at (0, 0, 2.5) looking along +x, 320 x 240, horizontal fov 0.8; the lamps'
# faces 7.82 m ahead; signal 7 (red 2.8 m, yellow 2.5 m, green 2.2 m high) 1 m to the right,
# signal 8 (a pedestrian light: red 2.52 m, green 2.18 m) 1 m to the left.
W, H, HFOV, DEPTH = 320, 240, 0.8, 7.82
F = (W / 2) / math.tan(HFOV / 2)


def pixel(y, z):
    return int(W / 2 - F * y / DEPTH), int(H / 2 - F * (z - 2.5) / DEPTH)


LAMPS = {"red": pixel(-1, 2.8), "yellow": pixel(-1, 2.5), "green": pixel(-1, 2.2),
         "ped_red": pixel(1, 2.52), "ped_green": pixel(1, 2.18)}

# A python_json engine sending the traffic_lights engine's datapack on a schedule: nothing
# before 0.5 s, then a state (vehicle light 7, pedestrian light 8) every half second.
SCHEDULE = [(0.5, "green", "red"), (1.0, "yellow", "red"), (1.5, "red", "green"),
            (2.0, "red_yellow", "red"), (2.5, "off", "off")]
LIGHTS = textwrap.dedent("""\
    from nrp_core.engines.python_json import EngineScript
    SCHEDULE = {schedule!r}
    class Script(EngineScript):
        def initialize(self):
            self._registerDataPack("traffic_lights")
        def runLoop(self, timestep_ns):
            t = self._time_ns * 1e-9
            now = [s for s in SCHEDULE if s[0] <= t + 1e-9]
            if now:
                _, vehicle, pedestrian = now[-1]
                self._setDataPack("traffic_lights", {{"time_ns": self._time_ns,
                    "signals": {{"7": vehicle, "8": pedestrian}}, "junctions": {{}}}})
    """)

FORWARD = textwrap.dedent("""\
    from nrp_core import *
    from nrp_core.data.nrp_json import *

    @EngineDataPack(keyword='src', id=DataPackIdentifier('traffic_lights', 'lights'))
    @TransceiverFunction("gazebo")
    def forward(src):
        if src.isEmpty():
            return []
        dp = JsonDataPack("{name}", "gazebo")
        dp.data["signals"] = src.data["signals"]
        return [dp]
    """)

# Records, each step, the mean colour of a 5 x 5 patch at each lamp's centre, the states the
# lights engine gave, and (with FRAMES) the first frame of each state as PNG.
RECORD = textwrap.dedent("""\
    import json, os, struct, zlib
    import numpy as np
    from nrp_core import *

    LAMPS = {lamps!r}
    FRAMES = {frames!r}
    _saved, _last = set(), [None]

    def write_png(path, image):
        h, w, _ = image.shape
        raw = b"".join(b"\\x00" + image[row].tobytes() for row in range(h))
        def chunk(kind, data):
            return (struct.pack(">I", len(data)) + kind + data
                    + struct.pack(">I", zlib.crc32(kind + data)))
        with open(path, "wb") as f:
            f.write(b"\\x89PNG\\r\\n\\x1a\\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
                    + chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))

    @EngineDataPack(keyword='camera', id=DataPackIdentifier('rig_camera::cam', 'gazebo'))
    @EngineDataPack(keyword='lights', id=DataPackIdentifier('traffic_lights', 'lights'))
    @TransceiverFunction("gazebo")
    def record(camera, lights):
        if camera.isEmpty():
            return []
        c = camera.data
        image = np.frombuffer(c.image_data, np.uint8).reshape(c.image_height, c.image_width, 3)
        rec = {{"lamps": {{}},
               "states": None if lights.isEmpty() else lights.data["signals"]}}
        for name, (u, v) in LAMPS.items():
            rec["lamps"][name] = [float(x) for x in image[v - 2:v + 3, u - 2:u + 3].reshape(-1, 3).mean(0)]
        with open(os.path.join(os.path.dirname(__file__), "record.jsonl"), "a") as f:
            f.write(json.dumps(rec) + "\\n")
        # A state shows from the frame after the one it came with.
        state = "initial" if lights.isEmpty() else lights.data["signals"].get("7", "")
        shown, _last[0] = (state if state == _last[0] else None), state
        if FRAMES and shown and shown not in _saved:
            _saved.add(shown)
            os.makedirs(FRAMES, exist_ok=True)
            write_png(os.path.join(FRAMES, "%02d_%s.png" % (len(_saved), shown)), image)
        return []
    """)


def lit(rgb, channel):
    """A lamp lit in its colour: that channel bright."""
    return rgb[channel] > 200


def dark(rgb):
    return max(rgb) < 70


class TrafficLightState(unittest.TestCase):
    def experiment(self, lights_engine, timeout, name="traffic_lights", gazebo_extra=None,
                   frames=""):
        ex = Experiment(self)
        shutil.copy(WORLD, os.path.join(ex.dir, "world.sdf"))
        gz = {"EngineType": "gazebo_grpc", "EngineName": "gazebo", "GazeboWorldFile": "world.sdf",
              "EngineTimestep": 0.05}
        gz.update(gazebo_extra or {})
        ex.engines.append(gz)
        lights_engine(ex)
        ex.function("forward", FORWARD.format(name=name))
        ex.function("record", RECORD.format(lamps=LAMPS, frames=frames))
        ex.run(timeout)
        with open(os.path.join(ex.dir, "record.jsonl")) as f:
            return [json.loads(line) for line in f]

    def test_the_lamps_follow_the_state_a_python_engine_sends(self):
        def lights(ex):
            ex.engine("lights", LIGHTS.format(schedule=SCHEDULE), timestep=0.05)
        recs = self.experiment(lights, 3.0,
                               frames=os.environ.get("CONVOY_TRAFFIC_LIGHT_FRAMES", ""))
        self.assertEqual(len(recs), 61)  # at 0 (after Initialize), then every 0.05 s

        def at(t):  # the frame rendered at the end of the step ending at t
            return recs[int(round(t / 0.05))]["lamps"]

        # Before any state: red, the pedestrian light red too.
        r = at(0.25)
        self.assertTrue(lit(r["red"], 0), r)
        self.assertTrue(dark(r["yellow"]) and dark(r["green"]), r)
        self.assertTrue(lit(r["ped_red"], 0) and dark(r["ped_green"]), r)
        # Each state a quarter second after it was sent (it reaches the world a step later).
        r = at(0.75)  # green / red
        self.assertTrue(lit(r["green"], 1) and dark(r["red"]) and dark(r["yellow"]), r)
        self.assertTrue(lit(r["ped_red"], 0) and dark(r["ped_green"]), r)
        r = at(1.25)  # yellow
        self.assertTrue(lit(r["yellow"], 0) and lit(r["yellow"], 1), r)
        self.assertTrue(dark(r["red"]) and dark(r["green"]), r)
        r = at(1.75)  # red / green
        self.assertTrue(lit(r["red"], 0) and dark(r["green"]), r)
        self.assertTrue(lit(r["ped_green"], 1) and dark(r["ped_red"]), r)
        r = at(2.25)  # red_yellow
        self.assertTrue(lit(r["red"], 0) and lit(r["yellow"], 1) and dark(r["green"]), r)
        r = at(2.75)  # off: everything dark
        for name in LAMPS:
            self.assertTrue(dark(r[name]), (name, r))
        # The red lamp lit is red, not white: its green channel stays low.
        self.assertLess(at(0.25)["red"][1], 110)

    def test_the_traffic_lights_engine_drives_them(self):
        # city.xodr's junction 200: controller 2002 (signals 7 and 8) green for 1 s, yellow for
        # 1 s, then red for 1 s.
        def lights(ex):
            shutil.copy(CITY, os.path.join(ex.dir, "city.xodr"))
            ex.engines.append({"EngineType": "traffic_lights", "EngineName": "lights",
                               "EngineTimestep": 0.05, "Map": "city.xodr",
                               "Programs": {"200": [{"Duration": 1.0, "Green": ["2002"]},
                                                    {"Duration": 1.0, "Yellow": ["2002"]},
                                                    {"Duration": 1.0}]}})
        recs = self.experiment(lights, 3.0, name="junction_200",
                               gazebo_extra={"TrafficLightsDataPack": "junction_200"})
        seen = set()
        for i, rec in enumerate(recs[2:], 2):
            state = (recs[i - 2]["states"] or {}).get("7")  # two steps to reach the image
            if state != (recs[i - 1]["states"] or {}).get("7"):
                continue  # (changing)
            r = rec["lamps"]
            want = {"green": "green", "yellow": "yellow", "red": "red"}.get(state)
            if want is None:
                continue
            seen.add(state)
            channel = 1 if want == "green" else 0
            self.assertTrue(lit(r[want], channel), (i, state, r))
            for other in {"red", "yellow", "green"} - {want}:
                self.assertTrue(dark(r[other]), (i, state, other, r))
        self.assertEqual(seen, {"green", "yellow", "red"})

    def test_a_malformed_state_is_an_error_naming_engine_and_datapack(self):
        ex = Experiment(self)
        shutil.copy(WORLD, os.path.join(ex.dir, "world.sdf"))
        ex.engines.append({"EngineType": "gazebo_grpc", "EngineName": "gazebo",
                           "GazeboWorldFile": "world.sdf", "EngineTimestep": 0.05})
        ex.function("bad", textwrap.dedent("""\
            from nrp_core import *
            from nrp_core.data.nrp_json import *

            @TransceiverFunction("gazebo")
            def bad():
                dp = JsonDataPack("traffic_lights", "gazebo")
                dp.data["signals"] = {"7": 3}
                return [dp]
            """))
        r = ex.run(0.2, expect=3)
        self.assertIn("engine 'gazebo': datapack 'traffic_lights': signal '7': the state must be "
                      "a string, got 3", r.stderr)


if __name__ == "__main__":
    unittest.main()
