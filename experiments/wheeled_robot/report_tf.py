"""Sends the robot's pose, its camera frame and the camera's ground-truth boxes to the
logger."""
import numpy as np
from nrp_core import *
from nrp_core.data.nrp_json import *
from nrp_core.data.nrp_protobuf import GazeboCameraDataPack, GazeboLinkDataPack


@EngineDataPack(keyword='chassis', id=DataPackIdentifier('robot::chassis', 'gazebo'))
@EngineDataPack(keyword='camera', id=DataPackIdentifier('robot_camera::camera', 'gazebo'))
@EngineDataPack(keyword='boxes', id=DataPackIdentifier('robot_camera::camera::boxes', 'gazebo'))
@TransceiverFunction("logger")
def report(chassis, camera, boxes):
    if chassis.isEmpty():
        return []
    out = JsonDataPack("pose", "logger")
    out.data["x"] = float(chassis.data.position[0])
    out.data["y"] = float(chassis.data.position[1])
    out.data["speed"] = float((chassis.data.lin_vel[0] ** 2 + chassis.data.lin_vel[1] ** 2) ** 0.5)
    if not camera.isEmpty():
        c = camera.data
        out.data["frame"] = np.frombuffer(c.image_data, np.uint8).reshape(
            c.image_height, c.image_width, c.image_depth)
    if not boxes.isEmpty():
        out.data["seen"] = sorted(b["model"] for b in boxes.data["boxes"])
    return [out]
