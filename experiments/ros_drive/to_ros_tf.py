"""What the ROS side sees, through the ros_bridge engine "ros" (each datapack is published on
the topic named like it, stamped with the step's time):
  /convoy/route             nav_msgs/Path of the lane's waypoints, once (latched)
  /convoy/camera/image_raw  sensor_msgs/Image (and camera_info): the camera's latest frame,
                            every step, so that each step has an image and an odometry of
                            the same stamp (the driver pairs them with a TimeSynchronizer)
  /convoy/odom              nav_msgs/Odometry (and /tf) of the car's base_link"""
import csv
import os

from nrp_core import *
from nrp_core.data.nrp_json import *
from nrp_core.data.nrp_protobuf import GazeboCameraDataPack, GazeboLinkDataPack

ROUTE_FILE = os.path.join(os.environ.get("CONVOY_SHARE_DIR", ""), "models", "parkring_road",
                          "waypoints_lane-1.csv")
_route_sent = [False]


def route():
    with open(ROUTE_FILE) as f:
        return [[float(r["x"]), float(r["y"])] for r in csv.DictReader(f)]


@EngineDataPack(keyword='camera', id=DataPackIdentifier('smart_camera::camera', 'gazebo'))
@EngineDataPack(keyword='car', id=DataPackIdentifier('smart_car_link_plugin::base_link', 'gazebo'))
@TransceiverFunction("ros")
def to_ros(camera, car):
    out = []
    if not _route_sent[0]:
        out.append(JsonDataPack("/convoy/route", "ros", {"path": route()}))
        _route_sent[0] = True
    if not camera.isEmpty():
        image = GazeboCameraDataPack("/convoy/camera/image_raw", "ros")
        image.data = camera.data
        out.append(image)
    if not car.isEmpty():
        odom = GazeboLinkDataPack("/convoy/odom", "ros")
        odom.data = car.data
        out.append(odom)
    return out
