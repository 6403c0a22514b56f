"""The road users' information flow of a generated scenario run (make_config.py), one
transceiver function at the scenario engine's rate:

- every vehicle_agent and pedestrian_agent of the config gets its `neighbours` (the road users
  within 100 m: the other agents and the ego) and, with a traffic_lights engine, its
  `traffic_lights`;
- the world engine gets every agent, and every entity the scenario engine moves itself (its
  `entities`), as an actor (`agents`);
- the ego's planner (an engine named `planner`) gets its ground-truth input: the road users in
  the ego's frame, and a red (or too late yellow) light of the ego's approach as a standing
  object at the stop line, as experiments/city_traffic/traffic_tf.py does.

Engines come from the run's effective config ($CONVOY_RUN_DIR/config.json): agents by
EngineType, the world by `gazebo_grpc`, the ego's state `<EgoModel>::road_user` (the scenario
engine's Entities entry for its EgoName)."""

import json
import math
import os

from nrp_core import *  # noqa: F401,F403
from nrp_core.data.nrp_json import JsonDataPack
from nrp_core.data.nrp_protobuf import RoadUsersDataPack

from convoy_scenario.player import box_collisions
from convoy_traffic.ego_planner import ego_state, objects_from_road_users
from convoy_traffic.neighbours import neighbour_datapacks, road_users

HERE = os.path.dirname(os.path.abspath(__file__))
WORLD_CATEGORIES = ("car", "truck", "bus", "pedestrian", "cyclist")
STOP_LOOKAHEAD = 60.0    # m: a light of the ego's approach counts from this far
YELLOW_STOP_DECEL = 3.0  # m/s^2: on yellow the ego stops if it can with at most this


def _config():
    with open(os.path.join(os.environ.get("CONVOY_RUN_DIR", "."), "config.json")) as f:
        return json.load(f)


CONFIG = _config()
ENGINES = CONFIG.get("EngineConfigs", [])
AGENTS = [e["EngineName"] for e in ENGINES if e.get("EngineType") in ("vehicle_agent", "pedestrian_agent")]
LIGHTS = next((e for e in ENGINES if e.get("EngineType") == "traffic_lights"), None)
WORLD = next((e["EngineName"] for e in ENGINES if e.get("EngineType") == "gazebo_grpc"), None)
SCENARIO = next((e for e in ENGINES if e.get("EngineType") == "scenario"), None)
# the planner's input is built here unless perception_tf.py builds it (--perception sensors)
PLANNER = "planner" if any(e["EngineName"] == "planner" and "CONVOY_PERCEPTION=sensors" not in
                           e.get("EngineEnvParams", []) for e in ENGINES) else None
EGO_DP = None
if SCENARIO is not None:
    spec = (SCENARIO.get("Entities") or {}).get(SCENARIO.get("EgoName", "Ego"), "")
    if "/" in spec:
        EGO_DP = tuple(spec.split("/", 1))
LINK = SCENARIO["EngineName"] if SCENARIO is not None else (AGENTS[0] if AGENTS else None)
# entities the scenario engine moves itself (its `entities` datapack: RoadUsers as JSON)
PLAYED = SCENARIO is not None and "scenario" in (SCENARIO.get("Entities") or {}).values()

STOP_LINES = []
if LIGHTS is not None and PLANNER is not None:
    from convoy_scenario.stop_lines import stop_lines  # noqa: E402
    STOP_LINES = stop_lines(LIGHTS["Map"])


def _front(u):
    return (u.x + (u.length_offset + 0.5 * u.length) * math.cos(u.yaw),
            u.y + (u.length_offset + 0.5 * u.length) * math.sin(u.yaw))


def stop_line_object(ego, signals):
    """A RoadUser standing at the stop line of the ego's approach when its light says stop."""
    fx, fy = _front(ego)
    for line in STOP_LINES:
        d = line.ahead(fx, fy, ego.yaw)
        if d is None or d < -0.5 or d > STOP_LOOKAHEAD:
            continue
        state = signals.get(line.id, "off")
        stop = state in ("red", "red_yellow") or (
            state == "yellow" and ego.speed * ego.speed <= 2.0 * YELLOW_STOP_DECEL * max(d, 0.0))
        if not stop:
            return None
        u = type(ego)()
        u.id, u.category, u.model = "stop_line:" + line.id, "car", "stop_line"
        cx, cy = line.centre()
        u.x, u.y, u.yaw = cx + 0.1 * math.cos(line.heading), cy + 0.1 * math.sin(line.heading), line.heading
        u.length, u.width, u.length_offset = 0.2, 3.0, 0.0
        return u
    return None


_DRAWN = set()   # ids the world has been given


def _drawable(users):
    """The users the world may draw: a road user the scenario puts where another already is
    (a bike on a truck: the world refuses two boxes that overlap where they first appear) is
    drawn once it has left the other's box; the planner still gets it."""
    users = list(users)
    new = [u for u in users if u.id not in _DRAWN and not u.absent]
    if new:
        boxes = {u.id: {"x": u.x, "y": u.y, "yaw": u.yaw, "length": u.length, "width": u.width,
                        "length_offset": u.length_offset} for u in users if not u.absent}
        touching = box_collisions(boxes)
        for u in new:
            if not any(o in _DRAWN or o < u.id for o in touching.get(u.id, [])):
                _DRAWN.add(u.id)
    return [u for u in users if u.id in _DRAWN]


def _traffic(**dps):
    lights, ego_dp = dps.get("lights"), dps.get("ego")
    if ego_dp is not None and ego_dp.isEmpty():
        ego_dp = None
    agent_dps = [dps["a_%d" % i] for i in range(len(AGENTS))]
    if PLAYED:
        agent_dps.append(dps["played"])
    out = []
    signals = dict(lights.data["signals"]) if lights is not None and not lights.isEmpty() else {}
    everyone = agent_dps + ([ego_dp] if ego_dp is not None else [])
    out += neighbour_datapacks(everyone, agents=AGENTS, radius=100.0)
    if lights is not None and not lights.isEmpty():
        out += [JsonDataPack("traffic_lights", a, lights.data) for a in AGENTS]
    agents = road_users(agent_dps)
    if WORLD is not None:
        # the world draws road users; a scenario's MiscObjects (category "object") are not
        # drawn, but the planner still gets them as objects
        world = RoadUsersDataPack("agents", WORLD)
        world.data.users.extend(_drawable(u for u in agents if u.category in WORLD_CATEGORIES))
        out.append(world)
    if PLANNER is not None and ego_dp is not None:
        ego = ego_dp.data
        objs = [u for u in agents if not u.absent]
        line = stop_line_object(ego, signals)
        if line is not None:
            objs.append(line)
        e = ego_state(ego)
        out.append(JsonDataPack("planner_input", PLANNER, {
            "source": "ground_truth", "ego": e, "objects": objects_from_road_users(e, objs)}))
    return out


traffic = _traffic
for _i, _name in enumerate(AGENTS):
    traffic = EngineDataPack(keyword="a_%d" % _i, id=DataPackIdentifier("state", _name))(traffic)
if LIGHTS is not None:
    traffic = EngineDataPack(keyword="lights", id=DataPackIdentifier("traffic_lights", LIGHTS["EngineName"]))(traffic)
if EGO_DP is not None:
    traffic = EngineDataPack(keyword="ego", id=DataPackIdentifier(EGO_DP[1], EGO_DP[0]))(traffic)
if PLAYED:
    traffic = EngineDataPack(keyword="played", id=DataPackIdentifier("entities", SCENARIO["EngineName"]))(traffic)
traffic = TransceiverFunction(LINK)(traffic)
