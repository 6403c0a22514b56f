"""Camera stand-in: publishes an HxWx3 uint8 frame every step as a GazeboCameraDataPack,
the way the world engine does."""
import os

import numpy as np
from nrp_core.data.nrp_protobuf import GazeboCameraDataPack
from nrp_core.engines.python_json import EngineScript


class Script(EngineScript):
    def initialize(self):
        self.w = int(os.environ.get("IMG_W", 736))
        self.h = int(os.environ.get("IMG_H", 480))
        self.frame = np.random.default_rng(0).integers(0, 256, (self.h, self.w, 3), dtype=np.uint8)
        self.camera = GazeboCameraDataPack("camera", self._name)
        d = self.camera.data
        d.image_height, d.image_width, d.image_depth = self.h, self.w, 3
        d.image_data = self.frame.reshape(-1)
        self.seq = 0
        self._registerDataPack("camera")
        self._setDataPack("camera", self.camera)

    def runLoop(self, timestep_ns):
        self.seq += 1
        self.frame[0, 0, 0] = self.seq % 256  # a new frame every step
        self.frame[0, 0, 1] = (self.seq // 256) % 256
        self._setDataPack("camera", self.camera)
