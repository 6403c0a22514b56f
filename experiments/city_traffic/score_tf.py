"""The live driving score of a city_traffic run (docs/scoring.md, "Live scoring"): at the
agents' rate (20 Hz), feeds convoy_bench.live.LiveScore with the ego (the world's
`smart_car::road_user`), every agent's `state`, SUMO's `vehicles`, the world's `collisions`
and the lights' `traffic_lights`, against the route the run's ego driver follows (config.json)
on city.xodr; writes the score so far into summary.json every WRITE_EVERY samples and at the
last cycle before SimulationTimeout (update_summary: a live server also shows it on
/convoy/metrics), and each new infraction on /convoy/infractions. `convoy score RUN_DIR`
scores the same drive afterwards from tracks.jsonl. Without an ego (the density run) it does
nothing."""
import os
import sys

from nrp_core import *  # noqa: F401,F403

from convoy_bench import runs
from convoy_bench.live import LiveScore, summary_fields
from convoy_bench.run_files import load_config, run_dir, update_summary

try:
    import convoy_live  # the coordinator's live server, when the run has one
except ImportError:
    convoy_live = None

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import make_config  # noqa: E402
from convoy_scenario.stop_lines import stop_lines  # noqa: E402

WRITE_EVERY = 40  # samples: 2 s at 20 Hz
CONFIG = load_config()
ENGINES = {e["EngineName"] for e in CONFIG.get("EngineConfigs", [])}
HAS_EGO = "planner" in ENGINES
AGENTS = [n for n in ["car_%d" % i for i in range(len(make_config.VEHICLES))] +
          ["ped_%d" % i for i in range(len(make_config.PEDESTRIANS))] if n in ENGINES]
MAP = os.path.join(HERE, make_config.MAP)
TIMEOUT = float(CONFIG.get("SimulationTimeout") or 0.0)
DT = 0.05
_state = {"live": None, "n": 0, "final": False, "published": 0}


def _fields(u):
    return {"class": u.category, "x": u.x, "y": u.y, "yaw": u.yaw, "speed": u.speed,
            "length": u.length, "length_offset": u.length_offset}


def _start(ego):
    route_path, skip = runs._run_route(run_dir()) or (os.path.join(HERE, "ego_route.csv"), 0)
    points = runs.cut_route(runs.read_route_csv(route_path, skip), ego.x, ego.y)
    return LiveScore(points, MAP, stop_lines(MAP), ego=runs.EGO)


def _others(agents, sumo):
    others = {}
    for dp in agents:
        if dp is not None and not dp.isEmpty() and not dp.data.absent:
            others[dp.data.id] = _fields(dp.data)
    if sumo is not None and not sumo.isEmpty():
        for u in sumo.data.users:
            if not u.absent:
                others[u.id] = _fields(u)
    return others


def _publish_infractions(live):
    if convoy_live is None:
        return
    for e in live.events[_state["published"]:]:
        convoy_live.publish("/convoy/infractions", {"time_s": e["t"], "kind": e["kind"],
                                                    "other": e.get("other")})
    _state["published"] = len(live.events)


def _score(time_ns, ego, collisions, lights, sumo, **agents):
    if not HAS_EGO or _state["final"] or ego.isEmpty() or ego.data.absent:
        return []
    if _state["live"] is None:
        _state["live"] = _start(ego.data)
    live = _state["live"]
    t = time_ns * 1e-9
    e = ego.data
    cols = [] if collisions.isEmpty() else list(collisions.data)
    signals = {} if lights.isEmpty() else dict(lights.data.get("signals") or {})
    live.add(t, {"x": e.x, "y": e.y, "yaw": e.yaw, "speed": e.speed, "length": e.length,
                 "length_offset": e.length_offset}, _others(agents.values(), sumo), cols, signals)
    _state["n"] += 1
    _publish_infractions(live)
    final = TIMEOUT > 0 and t + DT > TIMEOUT + 1e-9
    if final or _state["n"] % WRITE_EVERY == 0:
        r = live.result(final=final)  # a city run has no timeout infraction (runs.score_run)
        if r is not None:
            update_summary(summary_fields(r, final))
        _state["final"] = final
    return []


score = _score
for _name in AGENTS:
    score = EngineDataPack(keyword=_name, id=DataPackIdentifier("state", _name))(score)
score = EngineDataPack(keyword="sumo", id=DataPackIdentifier("vehicles", "sumo"))(score)
score = EngineDataPack(keyword="lights", id=DataPackIdentifier("traffic_lights", "lights"))(score)
score = EngineDataPack(keyword="collisions", id=DataPackIdentifier("collisions", "gazebo"))(score)
score = EngineDataPack(keyword="ego", id=DataPackIdentifier("smart_car::road_user", "gazebo"))(score)
score = SimulationTime(keyword="time_ns")(score)
score = TransceiverFunction("lights")(score)
