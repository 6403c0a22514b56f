"""The scenario engine's transceiver function (list it in a config with a `scenario` engine:
{"Name": "scenario_tf", "FileName": "<share or repo>/python/convoy_scenario/scenario_tf.py"}).

At the scenario engine's rate it
- gives the scenario engine `road_users`: {"time_ns", "users": {entity: RoadUser dict}}, from
  each entity's state datapack as the engine's `Entities` maps them (a RoadUser, or a
  python_json road user's JSON dict);
- hands each commanded entity's engine its command (the scenario engine's `commands`) under
  the engine's `CommandDataPack` name, and the weather engine a run-time EnvironmentAction under
  its `ControlDataPack` name. Engines whose effective config has no such key (built without
  command inputs) get nothing.

Which engines, entities and names: the run's effective config ($CONVOY_RUN_DIR/config.json,
written by the coordinator before the functions load)."""

import json
import os

from nrp_core import *  # noqa: F401,F403
from nrp_core.data.nrp_json import JsonDataPack

ROAD_USER_FIELDS = ("id", "category", "model", "absent", "x", "y", "z", "yaw", "speed", "acceleration",
                    "yaw_rate", "vx", "vy", "length", "width", "height", "length_offset", "road",
                    "lane", "s", "t", "time_ns")


def _config():
    with open(os.path.join(os.environ.get("CONVOY_RUN_DIR", "."), "config.json")) as f:
        return json.load(f)


def road_user_dict(dp):
    """The RoadUser of a datapack as a dict (None when empty)."""
    if dp is None or dp.isEmpty():
        return None
    d = dp.data
    if isinstance(d, dict):
        return dict(d)
    if hasattr(d, "users") and not hasattr(d, "x"):   # a RoadUsers with one user
        if not len(d.users):
            return None
        d = d.users[0]
    return {k: getattr(d, k) for k in ROAD_USER_FIELDS}


def setup(config):
    """(scenario engine name, {entity: (engine, state dp, command dp name or None)},
    (weather engine, control dp) or None) from an effective config."""
    engines = config.get("EngineConfigs", [])
    by_name = {e["EngineName"]: e for e in engines}
    scen = [e for e in engines if e.get("EngineType") == "scenario"]
    if len(scen) != 1:
        raise RuntimeError("scenario_tf.py: the config needs exactly one engine of type "
                           "'scenario' (has %d)" % len(scen))
    scen = scen[0]
    from convoy_scenario import load
    scenario = load(scen["ScenarioFile"], parameters=scen.get("Parameters") or None)
    ego = scen.get("EgoName", "Ego")
    mapping = {}
    for ent in scenario.entities:
        spec = (scen.get("Entities") or {}).get(ent.name, ent.name)
        if spec == "scenario":     # moved by the scenario engine itself
            continue
        engine, dp = spec.split("/", 1) if "/" in spec else (spec, "state")
        if engine not in by_name:
            raise RuntimeError("scenario_tf.py: entity %r maps to engine %r, which the config "
                               "does not have" % (ent.name, engine))
        cmd = None
        if "/" not in spec and ent.name != ego:
            cmd = by_name[engine].get("CommandDataPack")
        mapping[ent.name] = (engine, dp, cmd)
    weather = None
    for e in engines:
        if e.get("EngineType") == "weather" and e.get("ControlDataPack"):
            weather = (e["EngineName"], e["ControlDataPack"])
            break
    return scen["EngineName"], mapping, weather


SCENARIO, ENTITIES, WEATHER = setup(_config())
_KEYS = {}


def _scenario_tf(commands, **states):
    out = []
    users = {}
    for name, key in sorted(_KEYS.items()):
        u = road_user_dict(states.get(key))
        if u is not None:
            users[name] = u
    out.append(JsonDataPack("road_users", SCENARIO, {"users": users}))
    if not commands.isEmpty():
        c = commands.data
        by_engine = c.get("entities") or {}
        for name, (engine, _, cmd_dp) in sorted(ENTITIES.items()):
            if cmd_dp and engine in by_engine:
                out.append(JsonDataPack(cmd_dp, engine, by_engine[engine]))
        if WEATHER is not None and c.get("weather"):
            out.append(JsonDataPack(WEATHER[1], WEATHER[0], c["weather"]))
    return out


scenario_tf = _scenario_tf
for _i, (_name, (_engine, _dp, _)) in enumerate(sorted(ENTITIES.items())):
    _KEYS[_name] = "entity_%d" % _i
    scenario_tf = EngineDataPack(keyword=_KEYS[_name], id=DataPackIdentifier(_dp, _engine))(scenario_tf)
scenario_tf = EngineDataPack(keyword="commands", id=DataPackIdentifier("commands", SCENARIO))(scenario_tf)
scenario_tf = TransceiverFunction(SCENARIO)(scenario_tf)
