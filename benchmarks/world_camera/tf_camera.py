import numpy as np
from nrp_core import *
from nrp_core.data.nrp_json import *
from nrp_core.data.nrp_protobuf import GazeboCameraDataPack


@EngineDataPack(keyword='camera', id=DataPackIdentifier('smart_camera::camera', 'gazebo'))
@TransceiverFunction("view")
def camera_to_view(camera):
    if camera.isEmpty():
        return []
    img = np.frombuffer(camera.data.image_data, np.uint8)
    return [JsonDataPack("frame", "view", {"h": camera.data.image_height, "w": camera.data.image_width,
                                           "mean": float(img[::97].mean()), "first": int(img[0])})]
