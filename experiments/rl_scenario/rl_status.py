"""The status function of convoy_gym's scenario episodes (python/convoy_gym/scenario_env.py,
multi_agent_env.py; configs written by convoy_gym/scenario_config.py).

Every step it returns done=True (so that each run_loop(1) of the client brings it back) and
one JSON observation: the time, the scenario engine's state (done, ending, reason), and every
road user's state (each vehicle_agent's and pedestrian_agent's `state`, the entities the
scenario engine moves itself) as RoadUser dicts keyed by id. The client derives everything
else (collisions, route progress, the live score) from these states, deterministically."""
import json
import os

from google.protobuf import json_format
from nrp_core import *  # noqa: F401,F403
from nrp_core.data.nrp_json import JsonRawData

KEYS = ("id", "category", "absent", "x", "y", "yaw", "speed", "acceleration", "yaw_rate", "vx", "vy",
        "length", "width", "length_offset", "road", "lane", "s", "t", "lights")


def _config():
    with open(os.path.join(os.environ.get("CONVOY_RUN_DIR", "."), "config.json")) as f:
        return json.load(f)


CONFIG = _config()
ENGINES = CONFIG.get("EngineConfigs", [])
AGENTS = [e["EngineName"] for e in ENGINES if e.get("EngineType") in ("vehicle_agent", "pedestrian_agent")]
SCENARIO = next(e for e in ENGINES if e.get("EngineType") == "scenario")
PLAYED = "scenario" in (SCENARIO.get("Entities") or {}).values()
LIGHTS = next((e["EngineName"] for e in ENGINES if e.get("EngineType") == "traffic_lights"), None)


def _user(d):
    if not isinstance(d, dict):
        d = json_format.MessageToDict(d, preserving_proto_field_name=True,
                                      including_default_value_fields=True)
    return {k: d.get(k) for k in KEYS if k in d}


def _status(time_ns, scenario, played=None, lights=None, **agents):
    users = {}
    for k in sorted(agents):
        dp = agents[k]
        if dp is None or dp.isEmpty():
            continue
        u = _user(dp.data)
        users[str(u.get("id") or AGENTS[int(k[2:])])] = u
    if played is not None and not played.isEmpty():
        for u in played.data.get("users") or []:
            u = _user(dict(u))
            users[str(u["id"])] = u
    sc = {} if scenario.isEmpty() else scenario.data
    obs = {"t": time_ns * 1e-9, "time_ns": int(time_ns), "users": users,
           "scenario": {"done": bool(sc.get("done")), "ending": bool(sc.get("ending")),
                        "reason": sc.get("reason")}}
    if lights is not None and not lights.isEmpty():
        obs["signals"] = dict(lights.data.get("signals") or {})
    return True, [JsonRawData(obs)]


rl_status = _status
for _i, _name in enumerate(AGENTS):
    rl_status = EngineDataPack(keyword="a_%d" % _i, id=DataPackIdentifier("state", _name))(rl_status)
if PLAYED:
    rl_status = EngineDataPack(keyword="played", id=DataPackIdentifier("entities", SCENARIO["EngineName"]))(rl_status)
if LIGHTS is not None:
    rl_status = EngineDataPack(keyword="lights", id=DataPackIdentifier("traffic_lights", LIGHTS))(rl_status)
rl_status = EngineDataPack(keyword="scenario", id=DataPackIdentifier("scenario", SCENARIO["EngineName"]))(rl_status)
rl_status = SimulationTime(keyword="time_ns")(rl_status)
rl_status = StatusFunction()(rl_status)
