"""Hands the recorder what it writes at the world's rate: the camera frame, the detector's
detections (when the run has an ego) and the world's collision records."""
import json
import os

import numpy as np
from nrp_core import *
from nrp_core.data.nrp_json import *
from nrp_core.data.nrp_protobuf import GazeboCameraDataPack


def _engines():
    try:
        with open(os.path.join(os.environ.get("CONVOY_RUN_DIR", "."), "config.json")) as f:
            return {e["EngineName"] for e in json.load(f)["EngineConfigs"]}
    except (OSError, ValueError, KeyError):
        return set()


def _record(collisions, camera=None, detections=None):
    out = JsonDataPack("observation", "recorder")
    if camera is not None and not camera.isEmpty():
        c = camera.data
        out.data["frame"] = np.frombuffer(c.image_data, np.uint8).reshape(c.image_height, c.image_width, c.image_depth)
    if detections is not None and not detections.isEmpty():
        out.data["detections"] = detections.data
    if not collisions.isEmpty():
        out.data["collisions"] = list(collisions.data)
    return [out]


# The ego's camera and detector, when the run has them (the density run has neither).
record = _record
if "yolo_detector" in _engines():
    record = EngineDataPack(keyword='detections', id=DataPackIdentifier('detections', 'yolo_detector'))(record)
    record = EngineDataPack(keyword='camera', id=DataPackIdentifier('smart_camera::camera', 'gazebo'))(record)
record = EngineDataPack(keyword='collisions', id=DataPackIdentifier('collisions', 'gazebo'))(record)
record = TransceiverFunction("recorder")(record)
