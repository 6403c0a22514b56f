"""Ground-truth boxes of the camera for the detector's ground_truth backend."""
from nrp_core import *
from nrp_core.data.nrp_json import *


@EngineDataPack(keyword='truth', id=DataPackIdentifier('smart_camera::camera::boxes', 'gazebo'))
@TransceiverFunction("yolo_detector")
def truth_to_detector(truth):
    if truth.isEmpty():
        return []
    return [JsonDataPack("boxes", "yolo_detector", {"boxes": truth.data["boxes"]})]
