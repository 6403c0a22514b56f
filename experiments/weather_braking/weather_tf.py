from nrp_core import *
from nrp_core.data.nrp_json import *


# The weather engine's state to the world engine (cameras, tyre friction, wind).
@EngineDataPack(keyword='weather', id=DataPackIdentifier('weather', 'weather'))
@TransceiverFunction("gazebo")
def weather_tf(weather):
    if weather.isEmpty():
        return []
    out = JsonDataPack("weather", "gazebo")
    out.data = weather.data
    return [out]
