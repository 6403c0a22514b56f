"""The client's action as the smart car's joint targets: both front wheels steer to `steer`
(rad), both rear wheels turn at `speed` (m/s) over the wheel radius."""
from nrp_core import *
from nrp_core.data.nrp_protobuf import GazeboJointDataPack

WHEEL_RADIUS = 0.3  # m
MAX_STEER = 0.55    # rad


@EngineDataPack(keyword='action', id=DataPackIdentifier('action', 'agent'))
@TransceiverFunction("gazebo")
def drive(action):
    if action.isEmpty():
        return []
    steer = max(-MAX_STEER, min(MAX_STEER, float(action.data["steer"])))
    omega = float(action.data["speed"]) / WHEEL_RADIUS
    out = []
    for joint in ("front_left_steering_joint", "front_right_steering_joint"):
        dp = GazeboJointDataPack("smart_car_joint_plugin::" + joint, "gazebo")
        dp.data.position = steer
        out.append(dp)
    for joint in ("rear_left_wheel_joint", "rear_right_wheel_joint"):
        dp = GazeboJointDataPack("smart_car_joint_plugin::" + joint, "gazebo")
        dp.data.velocity = omega
        out.append(dp)
    return out
