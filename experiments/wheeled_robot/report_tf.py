"""Sends the robot's pose (and what its camera sees, when there is a frame) to the logger."""
from nrp_core import *
from nrp_core.data.nrp_json import *
from nrp_core.data.nrp_protobuf import GazeboLinkDataPack


@EngineDataPack(keyword='chassis', id=DataPackIdentifier('robot::chassis', 'gazebo'))
@TransceiverFunction("logger")
def report(chassis):
    if chassis.isEmpty():
        return []
    out = JsonDataPack("pose", "logger")
    out.data["x"] = float(chassis.data.position[0])
    out.data["y"] = float(chassis.data.position[1])
    out.data["speed"] = float((chassis.data.lin_vel[0] ** 2 + chassis.data.lin_vel[1] ** 2) ** 0.5)
    return [out]
