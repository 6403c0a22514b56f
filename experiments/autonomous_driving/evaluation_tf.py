"""Hands the evaluator what it records: the camera frame, the detector's detections, the
camera's ground-truth boxes and the car's pose."""
import numpy as np
from nrp_core import *
from nrp_core.data.nrp_json import *
from nrp_core.data.nrp_protobuf import GazeboCameraDataPack, GazeboLinkDataPack


@EngineDataPack(keyword='camera', id=DataPackIdentifier('smart_camera::camera', 'gazebo'))
@EngineDataPack(keyword='truth', id=DataPackIdentifier('smart_camera::camera::boxes', 'gazebo'))
@EngineDataPack(keyword='car', id=DataPackIdentifier('smart_car_link_plugin::base_link', 'gazebo'))
@EngineDataPack(keyword='detections', id=DataPackIdentifier('detections', 'yolo_detector'))
@TransceiverFunction("evaluator")
def evaluate(camera, truth, car, detections):
    out = JsonDataPack("observation", "evaluator")
    if not car.isEmpty():
        out.data["x"] = float(car.data.pos[0])
        out.data["y"] = float(car.data.pos[1])
    if not camera.isEmpty():
        c = camera.data
        out.data["frame"] = np.frombuffer(c.image_data, np.uint8).reshape(c.image_height, c.image_width, c.image_depth)
    if not truth.isEmpty():
        out.data["truth"] = truth.data["boxes"]
    if not detections.isEmpty():
        out.data["detections"] = detections.data
    return [out]
