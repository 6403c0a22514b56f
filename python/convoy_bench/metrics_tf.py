"""The live driving score of a scenario run (docs/scoring.md, "Live scoring"): a transceiver
function at the scenario engine's rate that feeds live.LiveScore with the datapacks of each
step and writes the score into $CONVOY_RUN_DIR/summary.json: driving_score,
route_completion, infraction_penalty, infractions [{time, kind, other, ...}], nuplan_score, and
the whole result under "score".

Inputs (datapacks only; the config says which): the ego's RoadUser (the scenario engine's
Entities entry for its EgoName), the world's `collisions`, the traffic lights' `traffic_lights`
(when the config has a traffic_lights engine), every vehicle_agent's and pedestrian_agent's
`state`, the scenario engine's `route` and `scenario` (done), and the cycle's simulated time.
From the config it takes the names, the map (the scenario engine's Map) and SimulationTimeout.

It writes every WRITE_EVERY samples and at the end: when the scenario engine says done, or at
the last cycle before SimulationTimeout. At the end a route not finished is a scenario_timeout
infraction. Replaying the same datapacks gives the same summary fields, bit for bit.

In a live run (`convoy run --live`) each new infraction event goes to the viewers on
/convoy/infractions as it happens ({"time_s", "kind", "other", ...}), as do the infractions
the score finds when it is computed (min_speed, ...; each once), and the summary fields on
/convoy/metrics whenever they are written (run_files.update_summary)."""

import os

from nrp_core import *  # noqa: F401,F403

from convoy_bench.live import LiveScore, summary_fields
from convoy_bench.run_files import INFRACTIONS_TOPIC, load_config, publish_live, update_summary

WRITE_EVERY = 100   # samples (5 s at 20 Hz) between two scores of the drive so far in summary.json
HERE = os.path.dirname(os.path.abspath(__file__))


CONFIG = load_config()
ENGINES = CONFIG.get("EngineConfigs", [])
SCENARIO = next(e for e in ENGINES if e.get("EngineType") == "scenario")
WORLD = next((e["EngineName"] for e in ENGINES if e.get("EngineType") == "gazebo_grpc"), None)
LIGHTS = next((e for e in ENGINES if e.get("EngineType") == "traffic_lights"), None)
AGENTS = [e["EngineName"] for e in ENGINES if e.get("EngineType") in ("vehicle_agent", "pedestrian_agent")]
_spec = (SCENARIO.get("Entities") or {}).get(SCENARIO.get("EgoName", "Ego"), "gazebo/smart_car::road_user")
EGO_DP = tuple(_spec.split("/", 1)) if "/" in _spec else (_spec, "state")
EGO_ID = EGO_DP[1].split("::")[0] if "::" in EGO_DP[1] else EGO_DP[0]
TIMEOUT = float(CONFIG.get("SimulationTimeout") or 0.0)
DT = float(SCENARIO.get("EngineTimestep", 0.05))
MAP = SCENARIO.get("Map")
# entities the scenario engine moves itself (its `entities` datapack, docs/scenarios.md)
PLAYED = "scenario" in (SCENARIO.get("Entities") or {}).values()

STOP_LINES = []
if LIGHTS is not None:
    from convoy_scenario.stop_lines import stop_lines  # noqa: E402
    STOP_LINES = stop_lines(LIGHTS["Map"])

_state = {"live": None, "final": False, "n": 0, "events_sent": 0, "sent": set()}


def _user(dp):
    if dp is None or dp.isEmpty():
        return None
    d = dp.data
    if isinstance(d, dict):
        return d
    return {k: getattr(d, k) for k in ("id", "category", "absent", "x", "y", "yaw", "speed",
                                       "length", "length_offset")}


def _metrics(time_ns, route, scenario, ego, collisions, lights=None, **agents):
    if _state["final"]:
        return []
    if _state["live"] is None:
        if route.isEmpty() or len(route.data.get("points") or []) < 2:
            return []
        _state["live"] = LiveScore(route.data["points"], MAP, STOP_LINES, ego=EGO_ID)
    live = _state["live"]
    t = time_ns * 1e-9
    e = _user(ego)
    if e is not None and not e.get("absent"):
        others = {}
        users = [_user(agents[k]) for k in sorted(agents) if k != "played"]
        played = agents.get("played")
        if played is not None and not played.isEmpty():   # the scenario engine's own entities
            users += [dict(u) for u in played.data.get("users") or []]
        for u in users:
            if u is None or u.get("absent"):
                continue
            others[str(u["id"])] = {"class": u["category"], "x": float(u["x"]), "y": float(u["y"]),
                                    "yaw": float(u["yaw"]), "speed": float(u["speed"]),
                                    "length": float(u["length"]), "length_offset": float(u["length_offset"])}
        cols = [] if collisions is None or collisions.isEmpty() else list(collisions.data)
        signals = {} if lights is None or lights.isEmpty() else dict(lights.data.get("signals") or {})
        live.add(t, e, others, cols, signals)
        _state["n"] += 1
        _publish_events(live)
    done = not scenario.isEmpty() and bool(scenario.data.get("done"))
    final = done or (TIMEOUT > 0 and t + DT > TIMEOUT + 1e-9)
    if final or (_state["n"] and _state["n"] % WRITE_EVERY == 0):
        r = live.result(final=final, timed_out=final)
        if r is not None:
            fields = summary_fields(r, final)
            update_summary(fields)
            for i in fields["infractions"]:
                if i.get("time") is not None:
                    _publish_infraction(i["time"], i)
        _state["final"] = final
    return []


def _publish_infraction(t, infraction):
    """One infraction to the viewers of a live run, unless it was sent already."""
    key = (infraction.get("kind"), round(float(t), 6), str(infraction.get("other")))
    if key in _state["sent"]:
        return
    _state["sent"].add(key)
    msg = {"time_s": float(t), "kind": infraction.get("kind")}
    msg.update({k: v for k, v in infraction.items() if k not in ("t", "time", "kind")})
    publish_live(INFRACTIONS_TOPIC, msg)


def _publish_events(live):
    """The LiveScore events not sent yet (collisions, red lights), as they happen."""
    for ev in live.events[_state["events_sent"]:]:
        _publish_infraction(ev["t"], ev)
    _state["events_sent"] = len(live.events)


metrics = _metrics
for _i, _name in enumerate(AGENTS):
    metrics = EngineDataPack(keyword="a_%d" % _i, id=DataPackIdentifier("state", _name))(metrics)
if LIGHTS is not None:
    metrics = EngineDataPack(keyword="lights", id=DataPackIdentifier("traffic_lights", LIGHTS["EngineName"]))(metrics)
metrics = EngineDataPack(keyword="collisions", id=DataPackIdentifier("collisions", WORLD or EGO_DP[0]))(metrics)
metrics = EngineDataPack(keyword="ego", id=DataPackIdentifier(EGO_DP[1], EGO_DP[0]))(metrics)
metrics = EngineDataPack(keyword="scenario", id=DataPackIdentifier("scenario", SCENARIO["EngineName"]))(metrics)
metrics = EngineDataPack(keyword="route", id=DataPackIdentifier("route", SCENARIO["EngineName"]))(metrics)
if PLAYED:
    metrics = EngineDataPack(keyword="played", id=DataPackIdentifier("entities", SCENARIO["EngineName"]))(metrics)
metrics = SimulationTime(keyword="time_ns")(metrics)
metrics = TransceiverFunction(SCENARIO["EngineName"])(metrics)
