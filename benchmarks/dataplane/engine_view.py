"""Receiver: checks and times the frames relayed to it, in either form: a protobuf camera
datapack, or the report's JSON datapack 'camera_img' (c_imageHeight, c_imageWidth,
current_image_frame), turned into an image the report's way."""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from steptimer import StepTimer  # noqa: E402

from nrp_core.engines.python_json import EngineScript  # noqa: E402


class Script(EngineScript):
    def initialize(self):
        self.timer = StepTimer(self._name)
        self.w = int(os.environ.get("IMG_W", 736))
        self.h = int(os.environ.get("IMG_H", 480))
        self.fresh = 0
        self.bad = 0
        self.last = -1
        self._registerDataPack("camera_in")
        self._registerDataPack("camera_img")

    def _check(self, img, ):
        if img.shape != (self.h, self.w, 3):
            self.bad += 1
            return
        seq = int(img[0, 0, 0]) + 256 * int(img[0, 0, 1])
        if seq != self.last:
            self.fresh += 1
            self.last = seq

    def runLoop(self, timestep_ns):
        self.timer.tick()
        cam = self._getDataPack("camera_in")
        if cam is not None:
            self._check(cam.image_data.reshape(cam.image_height, cam.image_width, cam.image_depth))
        d = self._getDataPack("camera_img")
        if d is not None:
            # the report's yolo_detector_engine.py conversion
            img_list = d["current_image_frame"]
            img_frame = np.array(img_list, dtype=np.uint8)
            cv_image = img_frame.reshape((d["c_imageHeight"], d["c_imageWidth"], 3))
            self._check(cv_image)

    def shutdown(self):
        self.timer.dump(fresh=self.fresh, bad=self.bad, width=self.w, height=self.h)
