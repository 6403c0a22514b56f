"""The city's information flow, one transceiver function at the agents' rate (20 Hz):

- every vehicle and pedestrian agent gets its `neighbours` (road users within 100 m: the other
  agents, SUMO's vehicles and the ego) and the `traffic_lights` engine's signals;
- the traffic_lights engine leads SUMO's lights (`traffic_lights_in`) and reads SUMO's links;
- SUMO gets the ego and the vehicle agents as external road users, and a pedestrian agent
  while it is on the carriageway, so that SUMO's vehicles brake for them;
- the world engine gets every agent and SUMO vehicle as actors;
- the ego's planner gets its ground-truth input: the road users in the ego's frame, and a red
  (or too late yellow) light of the ego's approach as a standing object at the stop line, as
  CARLA's agents treat red lights;
- the recorder gets every road user's state, the signals and the planner's target.

The agents' names come from make_config.py, which wrote the config. Without a planner engine
(the density run) there is no ego: the ego's inputs and outputs are left out."""
import json
import os
import sys

from nrp_core import *
from nrp_core.data.nrp_json import JsonDataPack
from nrp_core.data.nrp_protobuf import RoadUsersDataPack

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import city_map  # noqa: E402
import make_config  # noqa: E402
from convoy_traffic.ego_planner import ego_state, objects_from_road_users  # noqa: E402
from convoy_traffic.neighbours import neighbour_datapacks, road_users  # noqa: E402


def _engines():
    """The run's engine names (the coordinator keeps the config in the run folder)."""
    try:
        with open(os.path.join(os.environ.get("CONVOY_RUN_DIR", "."), "config.json")) as f:
            return {e["EngineName"] for e in json.load(f)["EngineConfigs"]}
    except (OSError, ValueError, KeyError):
        return set()


HAS_EGO = "planner" in _engines()  # the density run has no ego
VEHICLES = ["car_%d" % i for i in range(len(make_config.VEHICLES))]
PEDESTRIANS = ["ped_%d" % i for i in range(len(make_config.PEDESTRIANS))]
AGENTS = VEHICLES + PEDESTRIANS
EGO = "smart_car"
MAP = city_map.CityMap(os.path.join(HERE, make_config.MAP))

_in_sumo = set()  # pedestrians currently put into SUMO


def _traffic(**dps):
    lights, tin, sumo_tl = dps["lights"], dps["tin"], dps["sumo_tl"]
    sumo, ego_dp, target = dps["sumo"], dps.get("ego"), dps.get("target")
    if ego_dp is not None and ego_dp.isEmpty():
        ego_dp = None
    agent_dps = [dps[a] for a in AGENTS]
    out = []
    # Lights: this engine leads SUMO.
    if not sumo_tl.isEmpty():
        out.append(JsonDataPack("sumo_traffic_lights", "lights", sumo_tl.data))
    if not tin.isEmpty():
        out.append(JsonDataPack("traffic_lights_in", "sumo", tin.data))
    signals = dict(lights.data["signals"]) if not lights.isEmpty() else {}

    # Every agent's view.
    everyone = agent_dps + [sumo] + ([ego_dp] if ego_dp is not None else [])
    out += neighbour_datapacks(everyone, agents=AGENTS, radius=100.0)
    if not lights.isEmpty():
        out += [JsonDataPack("traffic_lights", a, lights.data) for a in AGENTS]

    agents = road_users(agent_dps)
    by_id = {u.id: u for u in agents}
    # SUMO: the ego, the vehicle agents, and pedestrians on the carriageway (as small cars).
    ext = RoadUsersDataPack("external_road_users", "sumo")
    for a in VEHICLES:
        if a in by_id:
            ext.data.users.append(by_id[a])
    for p in PEDESTRIANS:
        u = by_id.get(p)
        on_road = u is not None and not u.absent and MAP.on_carriageway(u.road, u.lane)
        if on_road:
            v = ext.data.users.add()
            v.CopyFrom(u)
            v.category, v.model = "car", ""
            v.length, v.width, v.length_offset = 0.6, 0.8, 0.0
            _in_sumo.add(p)
        elif p in _in_sumo:
            v = ext.data.users.add()
            v.id, v.absent = p, True
            _in_sumo.discard(p)
    if ego_dp is not None:
        ext.data.users.append(ego_dp.data)
    out.append(ext)

    # The world: agents and SUMO's vehicles as actors.
    world = RoadUsersDataPack("agents", "gazebo")
    world.data.users.extend(agents)
    out.append(world)
    if not sumo.isEmpty():
        sv = RoadUsersDataPack("sumo_vehicles", "gazebo")
        sv.data.CopyFrom(sumo.data)
        out.append(sv)

    # The ego's planner (ground truth) and the recorder.
    sumo_users = road_users([sumo])
    others = [u for u in agents + sumo_users if not u.absent]
    rec = {"signals": signals, "users": []}
    for u in others + ([ego_dp.data] if ego_dp is not None else []):
        rec["users"].append([u.id, u.category, round(u.x, 3), round(u.y, 3), round(u.yaw, 4),
                             round(u.speed, 3), round(u.length, 2), round(u.length_offset, 2)])
    if target is not None and not target.isEmpty():
        rec["target"] = {k: target.data[k] for k in ("speed", "mode", "lead", "gap_m", "ttc_s")
                         if k in target.data}
    if ego_dp is not None:
        ego = ego_dp.data
        objs = list(others)
        line = city_map.stop_line_object(MAP.stop_lines, ego, signals)
        if line is not None:
            objs.append(line)
        e = ego_state(ego)
        out.append(JsonDataPack("planner_input", "planner", {
            "source": "ground_truth", "ego": e, "objects": objects_from_road_users(e, objs)}))
    out.append(JsonDataPack("traffic", "recorder", rec))
    return out


traffic = _traffic
for _name in AGENTS:
    traffic = EngineDataPack(keyword=_name, id=DataPackIdentifier("state", _name))(traffic)
traffic = EngineDataPack(keyword="lights", id=DataPackIdentifier("traffic_lights", "lights"))(traffic)
traffic = EngineDataPack(keyword="tin", id=DataPackIdentifier("traffic_lights_in", "lights"))(traffic)
traffic = EngineDataPack(keyword="sumo_tl", id=DataPackIdentifier("traffic_lights", "sumo"))(traffic)
traffic = EngineDataPack(keyword="sumo", id=DataPackIdentifier("vehicles", "sumo"))(traffic)
if HAS_EGO:
    traffic = EngineDataPack(keyword="ego", id=DataPackIdentifier("smart_car::road_user", "gazebo"))(traffic)
    traffic = EngineDataPack(keyword="target", id=DataPackIdentifier("target", "planner"))(traffic)
traffic = TransceiverFunction("lights")(traffic)
