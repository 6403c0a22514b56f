from nrp_core import *
from nrp_core.data.nrp_json import *
from nrp_core.data.nrp_protobuf import GazeboJointDataPack

WHEELS = ("front_left_wheel_joint", "front_right_wheel_joint",
          "rear_left_wheel_joint", "rear_right_wheel_joint")


# The driver's command to the car: the rear wheels' velocity targets, straight steering, and
# a brake torque on every wheel (smart_car_brake_plugin).
@EngineDataPack(keyword='command', id=DataPackIdentifier('command', 'braking_driver'))
@TransceiverFunction("gazebo")
def drive_tf(command):
    out = []
    for joint in ("rear_left_wheel_joint", "rear_right_wheel_joint"):
        j = GazeboJointDataPack("smart_car_joint_plugin::" + joint, "gazebo")
        j.data.velocity = command.data["wheel_velocity"]
        out.append(j)
    for joint in ("front_left_steering_joint", "front_right_steering_joint"):
        j = GazeboJointDataPack("smart_car_joint_plugin::" + joint, "gazebo")
        j.data.position = 0.0
        out.append(j)
    for joint in WHEELS:
        b = GazeboJointDataPack("smart_car_brake_plugin::" + joint, "gazebo")
        b.data.effort = command.data["brake"]
        out.append(b)
    return out
