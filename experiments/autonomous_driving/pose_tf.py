"""Hands the evaluator the car's pose (control-only runs: no camera)."""
from nrp_core import *
from nrp_core.data.nrp_json import *
from nrp_core.data.nrp_protobuf import GazeboLinkDataPack


@EngineDataPack(keyword='car', id=DataPackIdentifier('smart_car_link_plugin::base_link', 'gazebo'))
@TransceiverFunction("evaluator")
def pose_to_evaluator(car):
    if car.isEmpty():
        return []
    return [JsonDataPack("observation", "evaluator", {"x": float(car.data.pos[0]), "y": float(car.data.pos[1])})]
