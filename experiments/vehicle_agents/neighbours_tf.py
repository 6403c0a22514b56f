"""Gives every vehicle agent its neighbours (road users within 100 m) and the lights."""

from nrp_core import *
from nrp_core.data.nrp_json import JsonDataPack
from convoy_traffic.neighbours import neighbour_datapacks

AGENTS = ["car_%d" % i for i in range(8)]


@EngineDataPack(keyword="lights", id=DataPackIdentifier("traffic_lights", "lights"))
@EngineDataPack(keyword="car_0", id=DataPackIdentifier("state", "car_0"))
@EngineDataPack(keyword="car_1", id=DataPackIdentifier("state", "car_1"))
@EngineDataPack(keyword="car_2", id=DataPackIdentifier("state", "car_2"))
@EngineDataPack(keyword="car_3", id=DataPackIdentifier("state", "car_3"))
@EngineDataPack(keyword="car_4", id=DataPackIdentifier("state", "car_4"))
@EngineDataPack(keyword="car_5", id=DataPackIdentifier("state", "car_5"))
@EngineDataPack(keyword="car_6", id=DataPackIdentifier("state", "car_6"))
@EngineDataPack(keyword="car_7", id=DataPackIdentifier("state", "car_7"))
@TransceiverFunction("car_0")
def neighbours(lights, car_0, car_1, car_2, car_3, car_4, car_5, car_6, car_7):
    states = [car_0, car_1, car_2, car_3, car_4, car_5, car_6, car_7]
    out = neighbour_datapacks(states, agents=AGENTS, radius=100.0)
    if not lights.isEmpty():
        out += [JsonDataPack("traffic_lights", a, lights.data) for a in AGENTS]
    # One line per second: where each agent is.
    t = car_0.data.time_ns if not car_0.isEmpty() else 0
    if t % 1000000000 == 0:
        print("t=%5.1f s  " % (t * 1e-9) + "  ".join(
            "%s %s:%d %4.1f m/s%s" % (s.data.id, s.data.road, s.data.lane, s.data.speed,
                                      " (gone)" if s.data.absent else "")
            for s in states if not s.isEmpty()))
    return out
