from nrp_core import *
from nrp_core.data.nrp_json import *


# The car's state and the road surface, for the driver.
@EngineDataPack(keyword='car', id=DataPackIdentifier('smart_car_link_plugin::base_link', 'gazebo'))
@EngineDataPack(keyword='weather', id=DataPackIdentifier('weather', 'weather'))
@TransceiverFunction("braking_driver")
def observe_tf(car, weather):
    state = JsonDataPack("state", "braking_driver")
    if car.isEmpty() or weather.isEmpty():
        return []
    state.data["x"] = car.data.position[0]
    state.data["y"] = car.data.position[1]
    state.data["vx"] = car.data.linear_velocity[0]
    state.data["vy"] = car.data.linear_velocity[1]
    state.data["surface"] = weather.data["surface"]
    state.data["mu"] = weather.data["mu"]
    return [state]
