#!/usr/bin/python3
"""Builds the default simulation config of an OpenSCENARIO file (what `convoy run --scenario`
runs; docs/scenarios.md, "Running a scenario"):

- the world engine on the world of the scenario's RoadNetwork LogicFile (MAPS below; for any
  other map a world generated from it, cached: worlds.py; --world FILE.sdf overrides), the ego
  (the report's smart car with its camera) inserted at its Init teleport;
- every other entity moved exactly by the scenario engine (its default controller: the
  player, player.py), except those with a driver-model or `convoy.*` controller, or `convoy.*`
  Properties (controllers.py): one vehicle_agent per such Vehicle and one pedestrian_agent per
  such Pedestrian, started at their Init teleports (StartPose) with their Init
  AbsoluteTargetSpeed (InitialSpeed, and a vehicle's desired speed v0 when its own AI drives
  it), sized from their BoundingBox, their model from the catalog entry or the vehicle's name
  when the actor-model table has it, else from the category;
- the weather engine with the Init EnvironmentActions; the traffic_lights engine when the map
  has traffic lights;
- the scenario engine (engines/scenario) driving the entities, and the ego: the report's PID
  waypoint follower (experiments/city_traffic/ego_driver.py) with the ego planner
  (ground-truth input), the camera and Convoy's detector, on the ego's route; with
  --perception sensors the smart car with a roof LiDAR (models/smart_car_lidar) whose planner
  drives on the detector's boxes ranged by the LiDAR (perception_tf.py; docs/scenarios.md,
  "Perception: ground truth or sensors");
- the transceiver functions (scenario_tf, traffic_tf, the ego's), the live driving score
  (python/convoy_bench/metrics_tf.py) and the status function that ends the run when the
  scenario is done.

The ego's route: its AssignRouteAction (the first one for the ego, Init or storyboard) if any,
else the lane it starts on followed onward (straight on at junctions) for RouteLength m: the
scenario's parameter RouteLength when declared, else 0.5 x 8.33 m/s x the StopTrigger's time
(60 s without one), within [40, 300] m. The follower gets the route 30 m longer so that it does
not stop short of the scored end.

Entity Properties named `convoy.<Key>` set that key of the entity's agent (e.g. `convoy.v0` 0
for a parked car, `convoy.MidBlockProbability`).

Usage: /usr/bin/python3 -m convoy_scenario.make_config SCENARIO.xosc --out CONFIG.json
           [--world WORLD.sdf] [--ego FRAGMENT.json] [--param NAME=VALUE]... [--bin-dir DIR]
           [--snapshots T1,T2] [--perception ground_truth|sensors]
The route CSV is written next to CONFIG.json (ego_route.csv). Every path in the config is
absolute. Exit 2 with one message on bad input."""

import argparse
import hashlib
import json
import math
import os
import re
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
PYTHON = os.path.dirname(HERE)
REPO = os.path.dirname(PYTHON)
if PYTHON not in sys.path:
    sys.path.insert(0, PYTHON)

from convoy_scenario import ScenarioError, load, weather_config  # noqa: E402
from convoy_scenario import model as m  # noqa: E402
from convoy_scenario.config_agents import (CATEGORY, DEFAULT_MODEL, actor_models, agent_config,  # noqa: E402,F401
                                           init_pose, pose_of, vehicle_model)
from convoy_scenario.config_exact import build_exact  # noqa: E402
from convoy_scenario.config_route import (cut, lane_of, lane_route, polyline_length,  # noqa: E402,F401
                                          route_points, surface_pose)
from convoy_scenario.controllers import agent_keys, controller_of  # noqa: E402
from convoy_scenario.controllers import kind as controller_kind  # noqa: E402
from convoy_scenario.odr import OdrQuery  # noqa: E402
from convoy_scenario.parsed import save_parsed  # noqa: E402
from convoy_scenario.player import Player  # noqa: E402
from convoy_scenario.roads import RoadMap  # noqa: E402
from convoy_scenario.worlds import generated_world  # noqa: E402

CITY = os.path.join(REPO, "experiments", "city_traffic")
AD = os.path.join(REPO, "experiments", "autonomous_driving")
# The project's maps: the .xodr -> the world without the ego (the ego is inserted at its Init).
MAPS = {
    os.path.join(CITY, "city.xodr"): os.path.join(CITY, "city_world_no_ego.sdf"),
    os.path.join(AD, "parkring.xodr"): os.path.join(AD, "parkring_road_no_ego.sdf"),
}
EGO_MODEL = os.path.join(CITY, "models", "smart_car", "model.sdf")
EGO_MODEL_LIDAR = os.path.join(CITY, "models", "smart_car_lidar", "model.sdf")
PERCEPTIONS = ("ground_truth", "sensors")
AGENT_DT = 0.05
WORLD_DT = 0.02
DETECTOR_DT = 0.1
CRUISE = 8.333              # the ego planner's cruise speed (experiments/city_traffic/ego_planner.json)
ROUTE_EXTRA_M = 30.0
DEFAULT_DURATION_S = 60.0
LONGEST_RUN_S = 120.0      # a StopTrigger's time beyond the ego's route time is cut here


def _file_id(path):
    with open(path, "rb") as f:
        return hashlib.sha1(f.read()).hexdigest()


def world_for(xodr):
    """The world SDF without ego for a project map (by path or identical content), or None."""
    real = os.path.realpath(xodr)
    for known, world in MAPS.items():
        if os.path.realpath(known) == real:
            return world
    digest = _file_id(xodr)
    for known, world in MAPS.items():
        if os.path.exists(known) and _file_id(known) == digest:
            return world
    return None


def engine_name(entity):
    name = re.sub(r"[^A-Za-z0-9_-]", "_", entity)
    return name if name and name[0].isalpha() else "e_" + name


def stop_time(scenario):
    """The earliest time the storyboard's StopTrigger fires by a ConditionGroup that is one
    SimulationTimeCondition (value + delay), or None."""
    best = None
    if scenario.stop_trigger is None:
        return None
    for group in scenario.stop_trigger.groups:
        if len(group) != 1:
            continue   # ANDed with another condition: no bound on its own
        c = group[0]
        if isinstance(c.test, m.SimulationTimeCondition) and c.test.rule in (
                "greaterThan", "greaterOrEqual", "equalTo"):
            v = c.test.value + c.delay
            best = v if best is None else min(best, v)
    return best


def init_actions(scenario, entity):
    return [a for a in scenario.init if a.entity == entity]


def ego_route_action(scenario, ego):
    """The first AssignRouteAction for the ego: Init's, else the storyboard's."""
    for a in init_actions(scenario, ego):
        if isinstance(a.spec, m.AssignRouteAction):
            return a.spec
    for story in scenario.stories:
        for act in story.acts:
            for grp in act.groups:
                if ego not in grp.actors:
                    continue
                for man in grp.maneuvers:
                    for ev in man.events:
                        for action in ev.actions:
                            if isinstance(action.spec, m.AssignRouteAction):
                                return action.spec
    return None


def properties(obj):
    """{Key: value} of the entity's Properties named convoy.<Key> (values read as JSON when
    they parse)."""
    out = {}
    for name, value in getattr(obj, "properties", ()):
        if name.startswith("convoy."):
            try:
                out[name[7:]] = json.loads(value)
            except ValueError:
                out[name[7:]] = value
    return out


def route_length(scenario):
    for name, value in scenario.parameters:
        if name == "RouteLength":
            return float(value)
    duration = stop_time(scenario) or DEFAULT_DURATION_S
    return max(40.0, min(300.0, 0.5 * CRUISE * duration))


def planner_config(perception, out_dir):
    """The ego planner's parameter file: the city's; for sensors a copy with Input "sensors"
    written into out_dir."""
    path = os.path.join(CITY, "ego_planner.json")
    if perception == "ground_truth":
        return path
    with open(path) as f:
        cfg = json.load(f)
    cfg["Input"] = perception
    out = os.path.join(os.path.abspath(out_dir), "ego_planner_%s.json" % perception)
    with open(out, "w") as f:
        json.dump(cfg, f, indent=2)
        f.write("\n")
    return out


def default_ego(world_sdf, pose, route_csv, out_engines, out_tfs, z=0.0, pitch=0.0, speed=0.0,
                perception="ground_truth", out_dir="."):
    """The report's smart car as the ego, at `pose` (x, y, yaw), rolling at the ego's Init
    `speed` (m/s; forward only: a negative one starts it at rest). With perception "sensors"
    the smart car carries a roof LiDAR and its planner takes perception_tf's objects."""
    x, y, yaw = pose
    model = EGO_MODEL_LIDAR if perception == "sensors" else EGO_MODEL
    out_engines[0]["GazeboSDFModels"] = [{"Name": "smart_car", "File": model,
                                          "InitPose": [x, y, z, 0.0, pitch, yaw],
                                          "InitSpeed": max(0.0, float(speed))}]
    # the smart car's meshes (model://smart_car/...) are found next to its model
    out_engines[0]["EngineEnvParams"] = ["CONVOY_MODEL_PATH=" + os.path.dirname(os.path.dirname(EGO_MODEL))]
    out_engines += [
        {"EngineType": "python_json", "EngineName": "car_ctl_engine",
         "PythonFileName": os.path.join(CITY, "ego_driver.py"), "EngineTimestep": WORLD_DT,
         "EngineEnvParams": ["CONVOY_EGO_ROUTE=" + route_csv, "CONVOY_EGO_ROUTE_SKIP=0"]},
        {"EngineType": "python_json", "EngineName": "planner",
         "PythonFileName": os.path.join(REPO, "experiments", "ego_planner", "ego_planner_engine.py"),
         "EngineTimestep": WORLD_DT,
         "EngineEnvParams": ["CONVOY_EGO_PLANNER_CONFIG=" + planner_config(perception, out_dir),
                             "CONVOY_EGO_ROUTE=" + route_csv, "CONVOY_PERCEPTION=" + perception]},
        {"EngineType": "detector", "EngineName": "yolo_detector", "Backend": "convoy",
         "EngineTimestep": DETECTOR_DT},
    ]
    out_tfs += [
        {"Name": "state_tf", "FileName": os.path.join(AD, "state_tf.py")},
        {"Name": "motor_tf", "FileName": os.path.join(REPO, "experiments", "ego_planner", "motor_tf.py")},
        {"Name": "camera_tf", "FileName": os.path.join(AD, "camera_tf.py")},
        {"Name": "detection_tf", "FileName": os.path.join(REPO, "python", "convoy_bench", "detection_tf.py")},
        {"Name": "perception_tf", "FileName": os.path.join(HERE, "perception_tf.py")},
    ]
    return "gazebo/smart_car::road_user"


def build(xosc, world=None, ego_fragment=None, parameters=None, out_dir=".", bin_dir=None, snapshots=None,
          scenery="auto", perception="ground_truth"):
    """(config dict, ego route points [[x, y, heading]], scored route length)."""
    scenario = load(xosc, parameters=parameters or None)
    base = os.path.basename(xosc)
    if perception not in PERCEPTIONS:
        raise ScenarioError("--perception %r: expected one of %s" % (perception, ", ".join(PERCEPTIONS)))
    if perception != "ground_truth" and ego_fragment:
        raise ScenarioError("--perception %s is the default ego's (the smart car's); it does not go "
                            "with --ego %s" % (perception, ego_fragment))
    if ego_fragment == "scenario":
        return build_exact(scenario, xosc, parameters, stop_time)
    if not scenario.logic_file:
        raise ScenarioError("%s: no RoadNetwork LogicFile: the stack under test needs an OpenDRIVE "
                            "map (its world, route and score); --ego scenario plays it without one" % base)
    world_sdf = os.path.abspath(world) if world else world_for(scenario.logic_file)
    if world_sdf is None:
        try:
            world_sdf = generated_world(scenario.logic_file, bin_dir, scenery, out_dir=out_dir)
        except ScenarioError as e:
            raise ScenarioError("%s: %s" % (base, e))
    if not os.path.exists(world_sdf):
        raise ScenarioError("%s: the world %s does not exist" % (base, world_sdf))
    names = [e.name for e in scenario.entities]
    ego = "Ego" if "Ego" in names else (names[0] if names else None)
    if ego is None:
        raise ScenarioError("%s: no entities" % base)
    models = actor_models()
    xodr = scenario.logic_file
    with OdrQuery(xodr, bin_dir) as odr:
        has_lights = bool(odr.info()["signals"])
        player = Player(scenario, RoadMap.open(xodr, bin_dir), [e.name for e in scenario.entities])
        ego_pose = init_pose(scenario, ego, player)
        if ego_pose is None:
            raise ScenarioError("%s: the ego %r has no Init TeleportAction (where does it start?)" % (base, ego))
        start = lane_of(odr, *ego_pose, "the ego's Init position")
        ego_surface = surface_pose(odr, ego_pose, start)
        length = route_length(scenario)
        spec = ego_route_action(scenario, ego)
        if spec is not None:
            pts, last = route_points(odr, spec, (start["road"], start["lane"], start["s"]), player)
            ext = odr.follow(last[0], last[1], last[2], ROUTE_EXTRA_M)["points"]
            scored_len = polyline_length(pts)
            drive = pts + ext[1:]
            scored = pts
        else:
            drive = odr.follow(start["road"], start["lane"], start["s"], length + ROUTE_EXTRA_M)["points"]
            scored = cut(drive, length)
            scored_len = polyline_length(scored)
        agents = []
        entity_map = {}
        for i, ent in enumerate(scenario.entities):
            if ent.name == ego:
                continue
            ctl = controller_of(scenario, ent.name)
            if controller_kind(ctl) != "driver" and not properties(ent.object):
                entity_map[ent.name] = "scenario"   # the default controller: exact control
                continue
            if init_pose(scenario, ent.name, player) is None:
                # a driver model with no start (esmini's SUMO controller stands for SUMO's
                # traffic): the scenario moves it, if its actions ever place it
                print("%s: entity %r has a driver-model controller but no Init position: the "
                      "scenario moves it" % (base, ent.name))
                entity_map[ent.name] = "scenario"
                continue
            name = engine_name(ent.name)
            entity_map[ent.name] = name
            a = agent_config(scenario, ent, i, name, odr, player, models, xodr)
            if ctl is not None:
                a.update(agent_keys(ctl))
            a.update(properties(ent.object))
            agents.append(a)

    route_csv = os.path.join(os.path.abspath(out_dir), "ego_route.csv")
    weather = {"EngineType": "weather", "EngineName": "weather", "EngineTimestep": AGENT_DT, "Seed": 0,
               "Surface": "dry", "Precipitation": 0.0, "Visibility": 20000.0, "WindSpeed": 0.0}
    init_weather = weather_config(scenario)
    if "SunAltitude" in init_weather:
        weather.pop("TimeOfDay", None)
    weather.update(init_weather)
    engines = [{"EngineType": "gazebo_grpc", "EngineName": "gazebo", "GazeboWorldFile": world_sdf,
                "GazeboRNGSeed": 7, "EngineTimestep": WORLD_DT, "ActorTimeout": 1.0}, weather]
    tfs = [{"Name": "weather_tf", "FileName": os.path.join(REPO, "experiments", "common", "weather_tf.py")}]
    if ego_fragment:
        with open(ego_fragment) as f:
            frag = json.load(f)
        engines += frag.get("EngineConfigs", [])
        tfs += frag.get("DataPackProcessingFunctions", [])
        ego_state = frag.get("EgoState", "gazebo/smart_car::road_user")
        if "GazeboSDFModels" in frag:
            engines[0]["GazeboSDFModels"] = frag["GazeboSDFModels"]
    else:
        ego_state = default_ego(world_sdf, ego_pose, route_csv, engines, tfs, *ego_surface,
                                speed=player.states[ego].speed, perception=perception, out_dir=out_dir)
    if has_lights:
        engines.append({"EngineType": "traffic_lights", "EngineName": "lights", "EngineTimestep": AGENT_DT,
                        "Map": xodr, "Leader": "self", "Green": 15.0, "Yellow": 3.0, "AllRed": 2.0})
    entity_map[ego] = ego_state
    engines.append({"EngineType": "scenario", "EngineName": "scenario", "EngineTimestep": AGENT_DT,
                    "ScenarioFile": os.path.abspath(xosc), "Parameters": dict(parameters or {}),
                    "Entities": entity_map, "EgoName": ego,
                    "EgoRoute": [[p[0], p[1]] for p in scored], "Map": xodr, "EndOnComplete": False})
    engines += agents
    tfs += [{"Name": "scenario_tf", "FileName": os.path.join(HERE, "scenario_tf.py")},
            {"Name": "traffic_tf", "FileName": os.path.join(HERE, "traffic_tf.py")},
            {"Name": "metrics_tf", "FileName": os.path.join(PYTHON, "convoy_bench", "metrics_tf.py")}]
    if snapshots:
        engines.append({"EngineType": "python_json", "EngineName": "snapshot", "EngineTimestep": WORLD_DT,
                        "PythonFileName": os.path.join(HERE, "snapshot.py"),
                        "EngineEnvParams": ["CONVOY_SNAPSHOT_TIMES=" + ",".join("%g" % t for t in snapshots)]})
        tfs.append({"Name": "snapshot_tf", "FileName": os.path.join(HERE, "snapshot_tf.py")})
    # the StopTrigger's time, but no longer than the ego's route at half its cruise speed or
    # LONGEST_RUN_S, whichever is longer (as CARLA's route timeout: a stack that cannot finish
    # its route does not hold the run for a scenario's 20-minute fallback)
    duration = stop_time(scenario)
    route_limit = max(20.0, math.ceil(scored_len / (0.5 * CRUISE)))
    timeout = min(duration + 0.5, max(route_limit, LONGEST_RUN_S)) if duration else route_limit
    config = {
        "SimulationName": "scenario_" + os.path.splitext(base)[0],
        "SimulationDescription": "Generated by python/convoy_scenario/make_config.py from %s" % os.path.abspath(xosc),
        "SimulationTimeout": timeout,
        "EngineConfigs": engines,
        "DataPackProcessingFunctions": tfs,
        "StatusFunction": {"Name": "scenario_status", "FileName": os.path.join(HERE, "status.py")},
    }
    return config, drive, scored_len


def write(xosc, out, world=None, ego=None, parameters=None, bin_dir=None, snapshots=None, scenery="auto",
          perception="ground_truth"):
    out_dir = os.path.dirname(os.path.abspath(out))
    os.makedirs(out_dir, exist_ok=True)
    config, drive, _ = build(xosc, world, ego, parameters, out_dir, bin_dir, snapshots, scenery, perception)
    # the scenario as read here, handed to the scenario engine (read once: parsed.py)
    parsed = os.path.join(out_dir, "scenario.parsed")
    save_parsed(load(xosc, parameters=parameters or None), xosc, parameters, parsed)
    for e in config["EngineConfigs"]:
        if e.get("EngineType") == "scenario":
            e["ParsedScenario"] = parsed
    with open(os.path.join(out_dir, "ego_route.csv"), "w") as f:
        f.write("x,y,heading\n")
        for x, y, h in drive:
            f.write("%.4f,%.4f,%.6f\n" % (x, y, h))
    with open(out, "w") as f:
        json.dump(config, f, indent=2)
        f.write("\n")
    return config


def _param(text):
    if "=" not in text:
        raise argparse.ArgumentTypeError("expected NAME=VALUE, got %r" % text)
    k, v = text.split("=", 1)
    try:
        return k, json.loads(v)
    except ValueError:
        return k, v


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("scenario")
    ap.add_argument("--out", required=True, help="the config file to write")
    ap.add_argument("--world", help="the world SDF (without the ego); default: the map's shipped world, "
                    "else one generated from the map (cached)")
    ap.add_argument("--scenery", default="auto", choices=["auto", "none", "roadside", "urban"],
                    help="the scenery of a generated world (auto: urban where the map has sidewalks)")
    ap.add_argument("--ego", help="a config fragment {EngineConfigs, DataPackProcessingFunctions, EgoState}: the user's ego; "
                    "'scenario': the scenario moves the ego too (config_exact.py)")
    ap.add_argument("--param", action="append", type=_param, default=[], help="NAME=VALUE: a scenario parameter")
    ap.add_argument("--bin-dir", help="where convoy-odr is")
    ap.add_argument("--snapshots", help="T1,T2,...: save the ego camera's frame at these simulated "
                    "seconds as camera_<t>s.png in the run folder (the default ego only)")
    ap.add_argument("--perception", default="ground_truth", choices=list(PERCEPTIONS),
                    help="the default ego's perception: ground_truth (the world's road users, the "
                    "default) or sensors (the detector's boxes ranged by a roof LiDAR, tracked)")
    a = ap.parse_args(argv)
    try:
        snaps = [float(t) for t in a.snapshots.split(",")] if a.snapshots else None
        write(a.scenario, a.out, a.world, a.ego, dict(a.param), a.bin_dir, snaps, a.scenery, a.perception)
    except ScenarioError as e:
        print("error: %s" % e, file=sys.stderr)
        return 2
    except OSError as e:
        print("error: %s: %s" % (getattr(e, "filename", "") or a.scenario, e.strerror), file=sys.stderr)
        return 2
    except ValueError as e:
        print("error: %s" % e, file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
