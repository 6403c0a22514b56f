from nrp_core import *
from nrp_core.data.nrp_protobuf import GazeboCameraDataPack


@EngineDataPack(keyword='camera', id=DataPackIdentifier('camera', 'cam'))
@TransceiverFunction("view")
def relay_camera(camera):
    if camera.isEmpty():
        return []
    out = GazeboCameraDataPack("camera_in", "view")
    out.data.image_height = camera.data.image_height
    out.data.image_width = camera.data.image_width
    out.data.image_depth = camera.data.image_depth
    out.data.image_data = camera.data.image_data
    return [out]
