"""The ROS side's answer as the smart car's joint targets (convoy_ros.control): a
convoy_msgs/Control on /convoy/control through the longitudinal model, else a
geometry_msgs/Twist on /cmd_vel. Nothing received yet: the car stands."""
from nrp_core import *
from nrp_core.data.nrp_json import *
from nrp_core.data.nrp_protobuf import GazeboJointDataPack

from convoy_ros.control import ControlModel, joint_targets, twist_to_drive

STEP = 0.02  # s, the loop's step: what an unstamped Control integrates over
_model = ControlModel(step_dt=STEP)


def _has(dp):
    return not dp.isEmpty() and bool(dp.data)


@EngineDataPack(keyword='control', id=DataPackIdentifier('/convoy/control', 'ros'))
@EngineDataPack(keyword='cmd_vel', id=DataPackIdentifier('/cmd_vel', 'ros'))
@TransceiverFunction("gazebo")
def drive(control, cmd_vel):
    if _has(control):
        speed, steer = _model.update(control.data)
    elif _has(cmd_vel):
        speed, steer = twist_to_drive(cmd_vel.data)
    else:
        speed, steer = 0.0, 0.0
    out = []
    for joint, (field, value) in joint_targets(speed, steer).items():
        dp = GazeboJointDataPack(joint, "gazebo")
        setattr(dp.data, field, value)
        out.append(dp)
    return out
