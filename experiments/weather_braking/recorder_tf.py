import numpy as np
from nrp_core import *
from nrp_core.data.nrp_json import *


# The car's camera, its speed and the weather, for the video.
@EngineDataPack(keyword='camera', id=DataPackIdentifier('smart_camera::camera', 'gazebo'))
@EngineDataPack(keyword='car', id=DataPackIdentifier('smart_car_link_plugin::base_link', 'gazebo'))
@EngineDataPack(keyword='weather', id=DataPackIdentifier('weather', 'weather'))
@TransceiverFunction("recorder")
def recorder_tf(camera, car, weather):
    out = JsonDataPack("observation", "recorder")
    if camera.isEmpty() or weather.isEmpty():
        return []
    c = camera.data
    out.data["frame"] = np.frombuffer(c.image_data, np.uint8).reshape(c.image_height, c.image_width, c.image_depth)
    if not car.isEmpty():
        v = car.data.linear_velocity
        out.data["speed"] = float((v[0] ** 2 + v[1] ** 2) ** 0.5)
    out.data["weather"] = weather.data
    return [out]
