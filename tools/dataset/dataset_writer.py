"""The dataset writer (a python_json engine any experiment can add; tools/dataset/make_dataset.py
adds it): each frame its TF (dataset_tf.py) hands it becomes a COCO record with instance masks
and depth (python/convoy_perception/coco.py), written to $CONVOY_DATASET_DIR (default: the
run folder's dataset/) with the prefix $CONVOY_DATASET_PREFIX. annotations.json is written
at shutdown. $CONVOY_DATASET_EXTRA: JSON fields added to each image record (seed, weather).
"""
import json
import os

import numpy as np
from nrp_core.engines.python_json import EngineScript

from convoy_perception.coco import CocoWriter


class Script(EngineScript):
    def initialize(self):
        self._registerDataPack("frame")
        self._setDataPack("frame", {})
        run_dir = os.environ.get("CONVOY_RUN_DIR", ".")
        self.folder = os.environ.get("CONVOY_DATASET_DIR") or os.path.join(run_dir, "dataset")
        self.prefix = os.environ.get("CONVOY_DATASET_PREFIX", "f")
        self.extra = json.loads(os.environ.get("CONVOY_DATASET_EXTRA", "{}"))
        self.writer = CocoWriter(self.folder)
        self.count = 0

    def runLoop(self, timestep_ns):
        f = self._getDataPack("frame")
        if not f or "image" not in f:
            return
        self._setDataPack("frame", {})
        extra = dict(self.extra, time_s=round(self._time_ns * 1e-9, 3))
        if "weather" in f:
            w = f["weather"]
            extra["weather"] = {k: w.get(k) for k in ("precipitation", "precipitation_type",
                                                      "visibility_m", "surface", "sun_altitude_deg")}
        self.writer.add("%s_%06d" % (self.prefix, self.count), np.asarray(f["image"], dtype=np.uint8),
                        f["boxes"], np.asarray(f["ids"]), f.get("depth"), extra)
        self.count += 1

    def shutdown(self):
        self.writer.write()
        print("dataset_writer: %d frames, %d annotations in %s" % (
            self.count, len(self.writer.annotations), self.folder), flush=True)
