"""A scenario played in-process with every entity moved by the player (what `convoy run
--scenario FILE --ego scenario` does, without the coordinator): for tests and quick
comparisons with esmini.

    /usr/bin/python3 -m convoy_scenario.play FILE.xosc [--out tracks.csv] [--dt 0.05]
        [--max-time 300] [--param NAME=VALUE]...

Writes tracks.csv (convoy_scenario.tracks) and prints how the storyboard ended. Exit 2 with one
message on bad input."""

import argparse
import json
import sys

from . import load
from .player import Player
from .player_state import NoRoads
from .roads import RoadMap
from .storyboard import ScenarioRuntimeError, Storyboard
from .tracks import TracksWriter
from .xmltree import ScenarioError


def play(path, dt=0.05, max_time=300.0, parameters=None, on_step=None, end_on_complete=False):
    """Plays the scenario; on_step(t, world) at each step (world: the states at t, before the
    step's actions). Returns (end time, reason: "stop_trigger", "storyboard_complete" or
    "max_time"). As esmini, a storyboard whose stories are all complete goes on until its
    StopTrigger (end_on_complete: it ends then)."""
    scenario = load(path, parameters=parameters or None)
    roads = RoadMap.open(scenario.logic_file) if scenario.logic_file else NoRoads()
    player = Player(scenario, roads, [e.name for e in scenario.entities], dt)
    board = Storyboard(scenario, end_on_complete=end_on_complete, resolve_position=player.resolve_xy)
    board.driving_lanes = player.driving_lanes if scenario.logic_file else None
    k = 0
    while True:
        t = k * dt
        world = player.world()
        if on_step is not None:
            on_step(t, world)
        if t > max_time + 1e-9:
            return t, "max_time"
        result = board.step(t, world)
        stopped = any(tr.element_type == "storyboard" and tr.transition == "stopTransition"
                      for tr in result.transitions)
        if stopped or (result.done and end_on_complete):
            return t, "stop_trigger" if stopped else "storyboard_complete"
        player.advance(result, t, dt)
        k += 1


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("scenario")
    ap.add_argument("--out", default="tracks.csv")
    ap.add_argument("--dt", type=float, default=0.05)
    ap.add_argument("--max-time", type=float, default=300.0)
    ap.add_argument("--param", action="append", default=[], help="NAME=VALUE")
    a = ap.parse_args(argv)
    params = {}
    for p in a.param:
        k, _, v = p.partition("=")
        try:
            params[k] = json.loads(v)
        except ValueError:
            params[k] = v
    writer = TracksWriter(a.out)
    try:
        t, reason = play(a.scenario, a.dt, a.max_time, params, writer.step)
    except (ScenarioError, ScenarioRuntimeError) as e:
        print("error: %s" % e, file=sys.stderr)
        return 2
    finally:
        writer.close()
    print("%s: ended at t=%.2f (%s)" % (a.scenario, t, reason))
    return 0


if __name__ == "__main__":
    sys.exit(main())
