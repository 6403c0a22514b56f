from nrp_core import *
from nrp_core.data.nrp_protobuf import GazeboJointDataPack


@TransceiverFunction("gazebo")
def drive():
    out = []
    for j in ("rear_left_wheel_joint", "rear_right_wheel_joint"):
        dp = GazeboJointDataPack("smart_car_joint_plugin::" + j, "gazebo")
        dp.data.velocity = 10.0
        out.append(dp)
    return out
