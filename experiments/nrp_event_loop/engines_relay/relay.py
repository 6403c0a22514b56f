"""Relays engine 1's time to engine 2, every EventLoop cycle, with the EventLoop's Clock."""
from nrp_core.data.nrp_json import JsonDataPack
from nrp_core.event_loop import *


@FromEngine(keyword="datapack1", address="/python_1/datapack1")
@Clock(keyword="clock")
@FunctionalNode(name="relay", outputs=["rec_datapack2"])
def relay(datapack1, clock):
    dp = JsonDataPack("rec_datapack2", "python_2")
    if datapack1 is not None and not datapack1.isEmpty():
        dp.data["engine_1_time_ms"] = datapack1.data["time_ms"]
    dp.data["event_loop_clock_ms"] = clock
    return [dp]


@FromFunctionalNode(keyword="dp", address="/relay/rec_datapack2")
@ToEngine(keyword="dp", address="/python_2")
@FunctionalNode(name="to_engine_2", outputs=["dp"])
def to_engine_2(dp):
    return [dp]
