import numpy as np
from nrp_core import *
from nrp_core.data.nrp_json import *
from nrp_core.data.nrp_protobuf import GazeboCameraDataPack


@EngineDataPack(keyword='camera', id=DataPackIdentifier('smart_camera::camera', 'gazebo'))  
@TransceiverFunction("yolo_detector")  
def detect_img(camera):
    if camera.isEmpty():
        return []
    trans_imgHeight = camera.data.image_height
    trans_imgWidth = camera.data.image_width
    trans_imgData_bytes = camera.data.image_data
    imgData = np.frombuffer(trans_imgData_bytes, np.uint8)

    processed_image = JsonDataPack("camera_img", "yolo_detector")  
  
    processed_image.data['c_imageHeight'] = trans_imgHeight  
    processed_image.data['c_imageWidth'] = trans_imgWidth  
    processed_image.data['current_image_frame'] = imgData 
    return [processed_image]
