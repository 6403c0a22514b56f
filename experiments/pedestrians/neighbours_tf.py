"""Gives every road user (2 vehicle agents, 6 pedestrian agents) its neighbours within 100 m,
vehicles and pedestrians alike, and the traffic_lights engine's signals; writes every road
user's track to tracks.jsonl and prints where each one is once per second."""

import json

from nrp_core import *
from nrp_core.data.nrp_json import JsonDataPack
from convoy_traffic.neighbours import neighbour_datapacks, road_users

AGENTS = ["car_0", "car_1"] + ["ped_%d" % i for i in range(6)]
_tracks = open("tracks.jsonl", "w")


@EngineDataPack(keyword="lights", id=DataPackIdentifier("traffic_lights", "lights"))
@EngineDataPack(keyword="car_0", id=DataPackIdentifier("state", "car_0"))
@EngineDataPack(keyword="car_1", id=DataPackIdentifier("state", "car_1"))
@EngineDataPack(keyword="ped_0", id=DataPackIdentifier("state", "ped_0"))
@EngineDataPack(keyword="ped_1", id=DataPackIdentifier("state", "ped_1"))
@EngineDataPack(keyword="ped_2", id=DataPackIdentifier("state", "ped_2"))
@EngineDataPack(keyword="ped_3", id=DataPackIdentifier("state", "ped_3"))
@EngineDataPack(keyword="ped_4", id=DataPackIdentifier("state", "ped_4"))
@EngineDataPack(keyword="ped_5", id=DataPackIdentifier("state", "ped_5"))
@TransceiverFunction("car_0")
def neighbours(lights, car_0, car_1, ped_0, ped_1, ped_2, ped_3, ped_4, ped_5):
    states = [car_0, car_1, ped_0, ped_1, ped_2, ped_3, ped_4, ped_5]
    out = neighbour_datapacks(states, agents=AGENTS, radius=100.0)
    if not lights.isEmpty():
        out += [JsonDataPack("traffic_lights", a, lights.data) for a in AGENTS]
    users = [s.data for s in states if not s.isEmpty()]
    t = users[0].time_ns if users else 0
    _tracks.write(json.dumps({"t": t * 1e-9, "users": {
        u.id: [round(u.x, 3), round(u.y, 3), round(u.speed, 3), u.absent] for u in users}}) + "\n")
    if t % 1000000000 == 0:
        print("t=%5.1f s  " % (t * 1e-9) + "  ".join(
            "%s %s:%d %4.2f m/s%s" % (u.id, u.road, u.lane, u.speed, " (gone)" if u.absent else "")
            for u in users))
    return out
