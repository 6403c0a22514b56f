"""The ego camera's frame to the snapshot engine (snapshot.py)."""
import numpy as np
from nrp_core import *  # noqa: F401,F403
from nrp_core.data.nrp_json import JsonDataPack


@EngineDataPack(keyword="camera", id=DataPackIdentifier("smart_camera::camera", "gazebo"))
@TransceiverFunction("snapshot")
def snapshot_tf(camera):
    if camera.isEmpty():
        return []
    c = camera.data
    img = np.frombuffer(c.image_data, np.uint8).reshape(c.image_height, c.image_width, c.image_depth)
    return [JsonDataPack("frame", "snapshot", {"image": img})]
