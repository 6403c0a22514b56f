"""End-to-end test of EngineType "detector": a python_json engine makes camera images, a
transceiver function sends them to the detector as the report's `camera_img` (numpy array,
so a MessagePack ext / blob), and another one reads the detector's `detections` back.
The YOLO model is make_models.py's YOLOv5 model with a fixed output.

Run with Debian's /usr/bin/python3 -m unittest test_detector_e2e (CONVOY_BIN_DIR: the build's
bin folder)."""

import json
import os
import shutil
import subprocess
import sys
import tempfile
import textwrap
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
BIN_DIR = os.environ.get("CONVOY_BIN_DIR") or os.path.join(HERE, "..", "..", "build", "bin")
CONVOY = os.path.join(BIN_DIR, "convoy")

CAM = textwrap.dedent("""\
    import numpy as np
    from nrp_core.engines.python_json import EngineScript

    class Script(EngineScript):
        def initialize(self):
            self._registerDataPack("img")
            self.runLoop(0)

        def runLoop(self, timestep_ns):
            img = np.full((240, 320, 3), 100, dtype=np.uint8)
            self._setDataPack("img", {"h": 240, "w": 320, "frame": img})
    """)

TF_SEND = textwrap.dedent("""\
    from nrp_core import *
    from nrp_core.data.nrp_json import *

    @EngineDataPack(keyword='img', id=DataPackIdentifier('img', 'cam'))
    @TransceiverFunction("det")
    def send(img):
        if img.isEmpty():
            return []
        d = img.data
        return [JsonDataPack("camera_img", "det", {"c_imageHeight": d["h"], "c_imageWidth": d["w"],
                                                   "current_image_frame": d["frame"]})]
    """)

TF_READ = textwrap.dedent("""\
    import json, os
    from nrp_core import *
    from nrp_core.data.nrp_json import *

    @EngineDataPack(keyword='det', id=DataPackIdentifier('detections', 'det'))
    @TransceiverFunction("cam")
    def read(det):
        with open(os.path.join(os.path.dirname(os.path.abspath(__file__)), "out.jsonl"), "a") as f:
            f.write(json.dumps(None if det.isEmpty() else det.data) + "\\n")
        return []
    """)


class DetectorE2E(unittest.TestCase):
    def test_yolo_detections_reach_a_transceiver_function(self):
        d = tempfile.mkdtemp(prefix="convoy-detector-")
        self.addCleanup(shutil.rmtree, d, True)
        subprocess.run([sys.executable, os.path.join(HERE, "make_models.py"), d], check=True)
        for name, text in (("cam.py", CAM), ("send.py", TF_SEND), ("read.py", TF_READ)):
            with open(os.path.join(d, name), "w") as f:
                f.write(text)
        cfg = {
            "SimulationName": "detector", "SimulationTimeout": 0.05,
            "EngineConfigs": [
                {"EngineType": "python_json", "EngineName": "cam", "PythonFileName": "cam.py",
                 "EngineTimestep": 0.01},
                {"EngineType": "detector", "EngineName": "det", "EngineTimestep": 0.01,
                 "Backend": "yolo", "ModelPath": "yolov5_test.onnx",
                 "ClassNamesFile": "classes3.txt"},
            ],
            "DataPackProcessingFunctions": [{"Name": "send", "FileName": "send.py"},
                                            {"Name": "read", "FileName": "read.py"}],
        }
        with open(os.path.join(d, "simulation_config.json"), "w") as f:
            json.dump(cfg, f)
        r = subprocess.run([CONVOY, "run", "-q", "-c", os.path.join(d, "simulation_config.json"),
                            "--run-dir", os.path.join(d, "run")],
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, timeout=120)
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(os.path.join(d, "out.jsonl")) as f:
            out = [json.loads(line) for line in f]
        seen = [o for o in out if o]
        self.assertTrue(seen, out)
        last = seen[-1]
        self.assertEqual((last["width"], last["height"]), (320, 240))
        dets = last["detections"]
        self.assertEqual([x["class"] for x in dets], ["dog", "car", "person"])
        self.assertAlmostEqual(dets[1]["confidence"], 0.72, places=5)
        self.assertEqual([round(dets[1][k], 3) for k in ("x_min", "y_min", "x_max", "y_max")],
                         [37.5, 50, 62.5, 70])
        self.assertGreaterEqual(last["frame"], 1)

    def test_bad_model_path_is_a_config_error(self):
        d = tempfile.mkdtemp(prefix="convoy-detector-")
        self.addCleanup(shutil.rmtree, d, True)
        cfg = {"SimulationName": "detector", "SimulationTimeout": 0.02,
               "EngineConfigs": [{"EngineType": "detector", "EngineName": "det",
                                  "Backend": "yolo", "ModelPath": "missing.onnx"}]}
        with open(os.path.join(d, "simulation_config.json"), "w") as f:
            json.dump(cfg, f)
        r = subprocess.run([CONVOY, "run", "-q", "-c", os.path.join(d, "simulation_config.json"),
                            "--run-dir", os.path.join(d, "run")],
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, timeout=60)
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("missing.onnx", r.stderr)


if __name__ == "__main__":
    unittest.main()
