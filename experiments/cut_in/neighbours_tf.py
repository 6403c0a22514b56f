"""Neighbour views for the vehicle agent (a RoadUsers datapack) and the Python driver (JSON:
{"users": [RoadUser dicts]}), and both states for the recorder."""

from google.protobuf import json_format

from nrp_core import *
from nrp_core.data.nrp_json import JsonDataPack
from convoy_traffic.neighbours import neighbour_datapacks, road_users


def _dict(u):
    return json_format.MessageToDict(u, preserving_proto_field_name=True,
                                     including_default_value_fields=True)


@EngineDataPack(keyword="car_0", id=DataPackIdentifier("state", "car_0"))
@EngineDataPack(keyword="cutter", id=DataPackIdentifier("state", "cutter"))
@TransceiverFunction("car_0")
def neighbours(car_0, cutter):
    out = neighbour_datapacks([car_0, cutter], agents=["car_0"], radius=100.0)
    users = [_dict(u) for u in road_users([car_0, cutter])]
    for u in users:
        u["time_ns"] = int(u.get("time_ns", 0))
    out.append(JsonDataPack("neighbours", "cutter",
                            {"users": [u for u in users if u["id"] != "cutter"]}))
    out.append(JsonDataPack("users", "recorder", {"users": users}))
    return out
