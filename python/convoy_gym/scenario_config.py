"""The config of a scenario episode for convoy_gym's scenario environments (scenario_env.py,
multi_agent_env.py): the config `convoy run --scenario` would run (make_config.build), with
the road users the client drives ("learning" entities) as kinematic agents the scenario never
commands, and no world engine.

- The ego (and every other learning entity) is a `vehicle_agent` (a `pedestrian_agent` for a
  Pedestrian) at its Init pose, named `rl_<entity>`; the scenario engine's `Entities` maps it
  to `rl_<entity>/state` (its state only: the storyboard's actions aimed at it are not applied)
  and the client sends its `command` datapack each step (docs/road_users.md, Commands).
- The other entities stay as make_config makes them: the scenario's player, or their own
  vehicle_agent / pedestrian_agent (their AI between the scenario's actions).
- No world engine (gazebo) and no camera: the agents are kinematic, collisions are the road
  users' bounding boxes overlapping (computed by the client), the live score is computed by
  the client (convoy_bench.live.LiveScore) from the states the status function returns
  (experiments/rl_scenario/rl_status.py).
"""
import json
import os

from convoy_scenario import ScenarioError, load
from convoy_scenario import make_config as mc
from convoy_scenario.config_agents import actor_models, agent_config, init_pose
from convoy_scenario.odr import OdrQuery
from convoy_scenario.parsed import save_parsed
from convoy_scenario.player import Player
from convoy_scenario.roads import RoadMap

_REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
STATUS = os.path.join(_REPO, "experiments", "rl_scenario", "rl_status.py")
PREFIX = "rl_"
ROUTE_M = 400.0     # m: a learning vehicle's route (but the ego's), its lane onward
DROPPED_TFS = ("weather_tf", "metrics_tf", "detection_tf", "snapshot_tf")


def engine_of(entity):
    return PREFIX + mc.engine_name(entity)


def _bin_dir():
    return os.environ.get("CONVOY_BIN_DIR") or os.path.join(_REPO, "build", "bin")


def build_episode_config(xosc, out_dir, learning=None, parameters=None, timeout=None):
    """Writes out_dir/scenario_episode.json; returns (config path, info) with info =
    {"ego": name, "learning": {entity: {"engine", "kind", "start": (x, y, yaw), "speed",
    "length", "width", "length_offset"}}, "route": [[x, y], ...] (the ego's scored route),
    "map": xodr, "timeout": s}. learning: the entities the client drives (default: the ego)."""
    xosc = os.path.abspath(xosc)
    if not os.path.isfile(xosc):
        raise FileNotFoundError("scenario %s not found" % xosc)
    base = os.path.basename(xosc)
    os.makedirs(out_dir, exist_ok=True)
    scenario = load(xosc, parameters=parameters or None)
    if not scenario.logic_file:
        raise ScenarioError("%s: no RoadNetwork LogicFile: a scenario episode needs an OpenDRIVE map"
                            % base)
    names = [e.name for e in scenario.entities]
    ego = "Ego" if "Ego" in names else names[0]
    learning = list(learning) if learning is not None else [ego]
    for n in learning:
        if n not in names:
            raise ValueError("%s: no entity %r to learn (entities: %s)" % (base, n, ", ".join(names)))
    xodr = scenario.logic_file
    bin_dir = _bin_dir()
    info = {"ego": ego, "learning": {}, "map": xodr}
    with OdrQuery(xodr, bin_dir) as odr:
        player = Player(scenario, RoadMap.open(xodr, bin_dir), names)
        models = actor_models()
        agents = []
        for i, ent in enumerate(scenario.entities):
            if ent.name not in learning:
                continue
            if init_pose(scenario, ent.name, player) is None:
                raise ScenarioError("%s: the learning entity %r has no Init TeleportAction" % (base, ent.name))
            a = agent_config(scenario, ent, i, engine_of(ent.name), odr, player, models, xodr)
            if a["EngineType"] == "vehicle_agent":
                a.pop("v0", None)
                a["LaneChanges"] = False
            agents.append(a)
            bb = ent.object.bounding_box
            st = player.states[ent.name]
            route = None
            if a["EngineType"] == "vehicle_agent":   # its own way onward (the ego: its scored route)
                loc = mc.lane_of(odr, st.x, st.y, st.h, "entity %r's Init position" % ent.name)
                route = [[float(p[0]), float(p[1])] for p in odr.follow(loc["road"], loc["lane"], loc["s"],
                                                                        ROUTE_M)["points"]]
            info["learning"][ent.name] = {
                "engine": a["EngineName"], "kind": "pedestrian" if ent.kind == "pedestrian" else "vehicle",
                "start": (st.x, st.y, st.h), "speed": st.speed, "length": float(bb.length),
                "width": float(bb.width), "route": route}
    frag_path = os.path.join(out_dir, "rl_ego_fragment.json")
    ego_agent = next(a for a in agents if a["EngineName"] == engine_of(ego)) if ego in learning else None
    frag = {"EngineConfigs": [ego_agent] if ego_agent else [],
            "EgoState": (engine_of(ego) + "/state") if ego_agent else None}
    if ego_agent is None:
        raise ValueError("%s: the ego %r must be a learning entity (a client drives the ego)" % (base, ego))
    with open(frag_path, "w") as f:
        json.dump(frag, f)
    # world=/dev/null: make_config wants a world file; the world engine is dropped below
    config, drive, _ = mc.build(xosc, world=os.devnull, ego_fragment=frag_path, parameters=parameters,
                                out_dir=out_dir, bin_dir=bin_dir)
    engines = [e for e in config["EngineConfigs"] if e.get("EngineType") != "gazebo_grpc"]
    scen = next(e for e in engines if e.get("EngineType") == "scenario")
    for name, spec in info["learning"].items():
        if name == ego:
            continue
        # an entity the scenario moved (player) or its own agent: now the client's agent
        engines = [e for e in engines if e.get("EngineName") != mc.engine_name(name)]
        engines.append(next(a for a in agents if a["EngineName"] == spec["engine"]))
        scen["Entities"][name] = spec["engine"] + "/state"
    parsed = os.path.join(out_dir, "scenario.parsed")
    save_parsed(scenario, xosc, parameters, parsed)
    scen["ParsedScenario"] = parsed
    scen["EndAtRouteEnd"] = True
    config["EngineConfigs"] = engines
    config["DataPackProcessingFunctions"] = [t for t in config["DataPackProcessingFunctions"]
                                             if t["Name"] not in DROPPED_TFS]
    config["StatusFunction"] = {"Name": "rl_status", "FileName": STATUS}
    if timeout is not None:
        config["SimulationTimeout"] = float(timeout)
    config["SimulationName"] = "rl_" + config["SimulationName"]
    path = os.path.join(out_dir, "scenario_episode.json")
    with open(path, "w") as f:
        json.dump(config, f, indent=1)
    info["route"] = [[float(p[0]), float(p[1])] for p in scen.get("EgoRoute") or []]
    info["learning"][ego]["route"] = info["route"]
    info["timeout"] = float(config["SimulationTimeout"])
    info["lights"] = any(e.get("EngineType") == "traffic_lights" for e in engines)
    return path, info
