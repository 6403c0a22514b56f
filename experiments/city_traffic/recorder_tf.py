"""Hands the recorder what it writes at the world's rate: the camera frame, the detector's
detections and the world's collision records."""
import numpy as np
from nrp_core import *
from nrp_core.data.nrp_json import *
from nrp_core.data.nrp_protobuf import GazeboCameraDataPack


@EngineDataPack(keyword='camera', id=DataPackIdentifier('smart_camera::camera', 'gazebo'))
@EngineDataPack(keyword='detections', id=DataPackIdentifier('detections', 'yolo_detector'))
@EngineDataPack(keyword='collisions', id=DataPackIdentifier('collisions', 'gazebo'))
@TransceiverFunction("recorder")
def record(camera, detections, collisions):
    out = JsonDataPack("observation", "recorder")
    if not camera.isEmpty():
        c = camera.data
        out.data["frame"] = np.frombuffer(c.image_data, np.uint8).reshape(c.image_height, c.image_width, c.image_depth)
    if not detections.isEmpty():
        out.data["detections"] = detections.data
    if not collisions.isEmpty():
        out.data["collisions"] = list(collisions.data)
    return [out]
