"""The weather engine's state to the engines that act on it: the world engine (cameras, tyre
friction, wind) and the road-user engines (docs/weather.md). Shared by the driving
experiments; each names its weather engine "weather"."""
from nrp_core import *
from nrp_core.data.nrp_json import *

from convoy_traffic.weather import weather_datapacks, weather_targets

_TARGETS = weather_targets()


@EngineDataPack(keyword='weather', id=DataPackIdentifier('weather', 'weather'))
@TransceiverFunction("weather")
def weather_tf(weather):
    return weather_datapacks(weather, _TARGETS)
