"""The pooled city's information flow (simulation_config_pooled*.json), one transceiver function
at the pool's rate (20 Hz):

- the world engine gets every pooled vehicle and walker as an actor: the pool's convoy.data.RoadUsers
  datapack is copied whole (binary protobuf, no JSON) to the world engine as `pool_users`;
- the pool gets the road users it does not drive as `external_users` (convoy.data.RoadUsers):
  the ego (the world engine's smart_car::road_user) and every vehicle_agent or
  pedestrian_agent engine of the run (its StateDataPack, read from the run's config.json).
  Its vehicles follow them, keep MOBIL's gaps to them and yield to them at junctions;
- the ego's planner gets its ground-truth input: the pooled vehicles and agents within
  PLANNER_RADIUS m of the ego, in the ego's frame;
- the recorder gets the ego and the road users within RECORD_RADIUS m of it (its per-user
  checks are Python; the whole pool is in the world engine, not in tracks.jsonl);
- with a traffic_lights engine in the run: its signals go to the pool (as the pool's
  TrafficLightsDataPack, when it names one) and to the recorder, and the ego's planner gets a
  red (or too late yellow) light of the ego's approach as a standing object at the stop line,
  as in the non-pooled city (traffic_tf.py): pooled vehicles, agents and the ego see the SAME
  lights."""
import json
import os
import sys

from nrp_core import *
from nrp_core.data.nrp_json import JsonDataPack
from nrp_core.data.nrp_protobuf import RoadUsersDataPack

from convoy_traffic.ego_planner import ego_state, objects_from_road_users
from convoy_traffic.neighbours import road_users

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import city_map  # noqa: E402

PLANNER_RADIUS = 100.0  # m
RECORD_RADIUS = 60.0    # m
AGENT_TYPES = ("vehicle_agent", "pedestrian_agent")


def _engines():
    """The run's engine configs (the coordinator keeps the config in the run folder)."""
    try:
        with open(os.path.join(os.environ.get("CONVOY_RUN_DIR", "."), "config.json")) as f:
            return json.load(f)["EngineConfigs"]
    except (OSError, ValueError, KeyError):
        return []


def _agents():
    """(engine name, state datapack name) of the run's agent engines."""
    return [(e["EngineName"], e.get("StateDataPack", "state")) for e in _engines()
            if e.get("EngineType") in AGENT_TYPES]


def _lights():
    """(engine name, datapack name) of the run's traffic_lights engine, the pool's
    TrafficLightsDataPack ("" when it keeps its own cycle) and the stop lines of the pool's map;
    None without a traffic_lights engine."""
    lights = [e for e in _engines() if e.get("EngineType") == "traffic_lights"]
    pool = [e for e in _engines() if e.get("EngineName") == "pool"]
    if not lights or not pool:
        return None
    stop_lines = city_map.CityMap(os.path.join(HERE, pool[0]["Map"])).stop_lines
    return (lights[0]["EngineName"], lights[0].get("DataPack", "traffic_lights"),
            pool[0].get("TrafficLightsDataPack", ""), stop_lines)


LIGHTS = _lights()


def _near(users, ex, ey, radius):
    r2 = radius * radius
    return [u for u in users if (u.x - ex) ** 2 + (u.y - ey) ** 2 < r2]


def pool_traffic(pool, ego, lights=None, **agents):
    if pool.isEmpty():
        return []
    world = RoadUsersDataPack("pool_users", "gazebo")
    world.data.CopyFrom(pool.data)
    out = [world]
    signals = {}
    if lights is not None and not lights.isEmpty():
        signals = dict(lights.data["signals"])
        if LIGHTS[2]:
            out.append(JsonDataPack(LIGHTS[2], "pool", lights.data))
    others = road_users(agents.values())
    external = RoadUsersDataPack("external_users", "pool")
    for u in ([] if ego.isEmpty() else [ego.data]) + others:
        external.data.users.add().CopyFrom(u)
    out.append(external)
    if ego.isEmpty():
        return out
    e = ego_state(ego.data)
    ex, ey = e["x"], e["y"]
    near = _near(list(pool.data.users) + others, ex, ey, PLANNER_RADIUS)
    line = city_map.stop_line_object(LIGHTS[3], ego.data, signals) if LIGHTS else None
    objects = objects_from_road_users(e, near + ([line] if line is not None else []))
    out.append(JsonDataPack("planner_input", "planner", {
        "source": "ground_truth", "ego": e, "objects": objects}))
    rec = {"signals": signals, "users": []}
    for u in _near(near, ex, ey, RECORD_RADIUS) + [ego.data]:
        rec["users"].append([u.id, u.category, round(u.x, 3), round(u.y, 3), round(u.yaw, 4),
                             round(u.speed, 3), round(u.length, 2), round(u.length_offset, 2)])
    walkers = sum(1 for u in pool.data.users if u.category == "pedestrian")
    rec["pool_size"] = len(pool.data.users) - walkers  # vehicles
    rec["pool_pedestrians"] = walkers
    out.append(JsonDataPack("traffic", "recorder", rec))
    return out


for _i, (_name, _dp) in enumerate(_agents()):
    pool_traffic = EngineDataPack(keyword="agent%d" % _i, id=DataPackIdentifier(_dp, _name))(pool_traffic)
if LIGHTS:
    pool_traffic = EngineDataPack(keyword="lights", id=DataPackIdentifier(LIGHTS[1], LIGHTS[0]))(pool_traffic)
pool_traffic = EngineDataPack(keyword="ego", id=DataPackIdentifier("smart_car::road_user", "gazebo"))(pool_traffic)
pool_traffic = EngineDataPack(keyword="pool", id=DataPackIdentifier("road_users", "pool"))(pool_traffic)
pool_traffic = TransceiverFunction("pool")(pool_traffic)
