"""Detection input of the ego planner: the detector's boxes, ranged in the smart car's camera's
depth image, in the ego's frame, labelled "detections". Velocities come from a tracker
(convoy_traffic.ego_planner.Tracker) over the detector's frames. Also feeds the detector the
camera's image (Convoy's trained detector, the config's backend) and its ground-truth boxes
(for the ground_truth backend, should a config choose it), poses the road user in the world
and hands it the ego's state and the world's collisions."""
import math

import numpy as np

from nrp_core import *
from nrp_core.data.nrp_json import JsonDataPack
from convoy_traffic.ego_planner import Tracker, ego_state, objects_from_detections

# The smart car's camera (models/smart_car/model.sdf): 736 x 480, horizontal fov 1.57, about
# 0.73 m ahead of base_link, looking along x (pitched down 0.076 rad: neglected).
HFOV, CAM_X = 1.57, 0.73
_state = {"tracker": Tracker(), "frame": None, "objects": []}


@EngineDataPack(keyword='ego', id=DataPackIdentifier('smart_car::road_user', 'gazebo'))
@EngineDataPack(keyword='road_user', id=DataPackIdentifier('state', 'traffic'))
@EngineDataPack(keyword='camera', id=DataPackIdentifier('smart_camera::camera', 'gazebo'))
@EngineDataPack(keyword='boxes', id=DataPackIdentifier('smart_camera::camera::boxes', 'gazebo'))
@EngineDataPack(keyword='depth', id=DataPackIdentifier('smart_camera::camera::depth', 'gazebo'))
@EngineDataPack(keyword='detections', id=DataPackIdentifier('detections', 'detector'))
@EngineDataPack(keyword='collisions', id=DataPackIdentifier('collisions', 'gazebo'))
@TransceiverFunction("planner")
def planner_input(ego, road_user, camera, boxes, depth, detections, collisions):
    out = []
    if not camera.isEmpty():
        out.append(JsonDataPack("camera_img", "detector", {
            "c_imageHeight": camera.data.image_height, "c_imageWidth": camera.data.image_width,
            "current_image_frame": np.frombuffer(camera.data.image_data, np.uint8)}))
    if not collisions.isEmpty():  # the road user records them (the tests assert on them)
        out.append(JsonDataPack("collisions", "traffic", {"list": list(collisions.data)}))
    if not road_user.isEmpty():
        out.append(JsonDataPack("road_users", "gazebo", {"users": [dict(road_user.data)]}))
    if not boxes.isEmpty():
        out.append(JsonDataPack("boxes", "detector", dict(boxes.data)))
    if ego.isEmpty():
        return out
    e = ego_state(ego.data)
    out.append(JsonDataPack("ego", "traffic", e))
    if not detections.isEmpty() and not depth.isEmpty() and "detections" in detections.data:
        det = detections.data
        if det.get("frame") != _state["frame"]:
            _state["frame"] = det.get("frame")
            d = depth.data
            objs = objects_from_detections(list(det["detections"]), d["depth"], int(d["width"]),
                                           int(d["height"]), HFOV, cam_x=CAM_X)
            _state["objects"] = _state["tracker"].update(objs, det.get("time_ns", 0) * 1e-9,
                                                         e["speed"])
    out.append(JsonDataPack("planner_input", "planner", {
        "source": "detections", "ego": e, "objects": _state["objects"]}))
    return out
