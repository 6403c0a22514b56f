"""Hands the lap evaluator the car's pose."""
from nrp_core import *
from nrp_core.data.nrp_json import *
from nrp_core.data.nrp_protobuf import GazeboLinkDataPack


@EngineDataPack(keyword='car', id=DataPackIdentifier('smart_car_link_plugin::base_link', 'gazebo'))
@TransceiverFunction("evaluator")
def pose_to_evaluator(car):
    if car.isEmpty():
        return []
    d = car.data
    return [JsonDataPack("pose", "evaluator", {
        "x": float(d.pos[0]), "y": float(d.pos[1]),
        "rot": [float(v) for v in d.rot], "lin_vel": [float(v) for v in d.lin_vel]})]
