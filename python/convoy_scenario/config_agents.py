"""The road-user engines of a scenario's entities with driver models (make_config.py; docs/
scenarios.md, "Running a scenario" and "Controllers"): one vehicle_agent per such Vehicle, one
pedestrian_agent per such Pedestrian, started where the scenario's Init puts them."""

import json
import os

from . import model as m
from .xmltree import ScenarioError

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
ACTOR_TABLE = os.path.join(REPO, "engines", "gazebo_grpc", "actors", "actor_models.json")
AGENT_DT = 0.05
CATEGORY = {"car": "car", "van": "car", "truck": "truck", "trailer": "truck", "semitrailer": "truck",
            "bus": "bus", "bicycle": "cyclist", "motorbike": "cyclist", "tram": "bus", "train": "bus"}
DEFAULT_MODEL = {"car": "sedan", "truck": "truck", "bus": "bus", "cyclist": "bicycle"}


def actor_models():
    with open(ACTOR_TABLE) as f:
        return json.load(f)["models"]


def vehicle_model(entity, category, models):
    """The actor model: the entity's Property `model`, its catalog entry or its name when the
    actor-model table has it, else the category's default."""
    prop = dict(entity.object.properties).get("model")
    for cand in ([prop] if prop else []) + ([entity.catalog.entry] if entity.catalog else []) + [entity.object.name]:
        if cand in models:
            return cand
    return DEFAULT_MODEL[category]


def init_pose(scenario, entity, player):
    """(x, y, yaw) where the entity starts (its Init actions applied by the player), or None
    when no Init action places it."""
    st = player.states[entity]
    return (st.x, st.y, st.h) if st.placed else None


def pose_of(player, position):
    """(x, y, yaw) of a model position (any kind) now."""
    x, y, _, h = player.world_pose_of(position)
    return x, y, (h if h is not None else 0.0)


def agent_config(scenario, ent, i, name, odr, player, models, xodr):
    """The vehicle_agent or pedestrian_agent config of entity ent (the i-th), engine `name`."""
    from .config_route import lane_of
    base = os.path.basename(scenario.path)
    pose = init_pose(scenario, ent.name, player)
    if pose is None:
        raise ScenarioError("%s: entity %r has no Init TeleportAction" % (base, ent.name))
    bb = ent.object.bounding_box
    if ent.kind == "vehicle":
        cat = CATEGORY.get(ent.object.category, "car")
        loc = lane_of(odr, *pose, "entity %r's Init position" % ent.name)
        onward = odr.follow(loc["road"], loc["lane"], loc["s"], 400.0)["lanes"][-1]
        for ia in (x for x in scenario.init if x.entity == ent.name):
            if isinstance(ia.spec, m.AssignRouteAction):  # routed to its last waypoint
                last = lane_of(odr, *pose_of(player, ia.spec.waypoints[-1].position),
                               "entity %r's route's last waypoint" % ent.name)
                onward = [last["road"], last["lane"]]
        wheelbase = None
        axles = dict(ent.object.axles)
        if "FrontAxle" in axles and "RearAxle" in axles:
            wheelbase = dict(axles["FrontAxle"])["positionX"] - dict(axles["RearAxle"])["positionX"]
        a = {"EngineType": "vehicle_agent", "EngineName": name, "EngineTimestep": AGENT_DT,
             "Map": xodr, "StartPose": {"x": pose[0], "y": pose[1], "yaw": pose[2]},
             "Route": {"to": "%s:%d" % (onward[0], onward[1])},
             "InitialSpeed": player.states[ent.name].speed, "Model": vehicle_model(ent, cat, models),
             "Category": cat, "Length": bb.length, "Width": bb.width, "Height": bb.height,
             "LaneChanges": False, "Seed": i}
        if not (wheelbase and 0 < wheelbase < bb.length) and bb.length <= 2.7:
            wheelbase = 0.6 * bb.length   # small vehicles without axles (a bicycle)
        if wheelbase and 0 < wheelbase < bb.length:
            a["Wheelbase"] = wheelbase
        if a["InitialSpeed"] > 0:
            a["v0"] = a["InitialSpeed"]   # its desired speed when its own AI drives
    else:
        loc = lane_of(odr, pose[0], pose[1], None, "pedestrian %r's Init position" % ent.name,
                      types=("sidewalk",))
        road_len = next(r["length"] for r in odr.info()["roads"] if r["id"] == loc["road"])
        to_s = loc["s"] + 60.0 if loc["s"] + 60.0 < road_len else max(0.0, loc["s"] - 60.0)
        a = {"EngineType": "pedestrian_agent", "EngineName": name, "EngineTimestep": AGENT_DT,
             "Map": xodr, "StartPose": {"x": pose[0], "y": pose[1], "yaw": pose[2]},
             "Route": {"to": "%s:%d" % (loc["road"], loc["lane"]), "to_s": to_s},
             "Seed": 100 + i, "Length": max(bb.length, 0.3), "Width": max(bb.width, 0.3),
             "Height": bb.height}
        speed = player.states[ent.name].speed
        if speed > 0:
            a["Speed"], a["SpeedSd"] = speed, 0.0
    return a
