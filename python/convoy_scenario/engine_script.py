"""The `scenario` engine (docs/scenarios.md, "The scenario engine"): executes an OpenSCENARIO
storyboard in lock-step with the other engines. It is a python_json EngineScript that the
`convoy-engine-scenario` program runs (engines/scenario), loading this file by its path; a config names it with
"EngineType": "scenario".

Config keys (engines/scenario/schema.json):
  ScenarioFile      the .xosc (required)
  Parameters        {name: value}: overrides of the scenario's global parameters
  Entities          {scenario entity: road user}: "ENGINE" (its RoadUser datapack `state`,
                    commanded through `command`), "ENGINE/DATAPACK" (a state only, e.g.
                    "gazebo/smart_car::road_user": never commanded), or "scenario": moved
                    by this engine itself (the player: exact scenario control, player.py);
                    default: each entity's own name as engine
  EgoName           the entity that is the ego (default "Ego"): never commanded
  EgoRoute          the ego's route: a CSV (x, y[, heading]) or [[x, y], ...]; published as
                    the `route` datapack (the live score reads it)
  EndAtRouteEnd     true (default): the scenario is done when the ego has passed its route's end
  EndOnComplete     true (default): the scenario is done when its storyboard completes (all
                    stories ended); false: only its StopTrigger, the route's end or the run's
                    SimulationTimeout end it (the generated configs: the ego drives on)
  Map               the .xodr for lane lookups (default the scenario's LogicFile)
  ParsedScenario    the scenario as `convoy run --scenario` read it (parsed.py): used when it
                    matches ScenarioFile and Parameters, else the file is read
  StopTriggerOnly   false (default); true: a storyboard whose stories are all complete goes on
                    until its StopTrigger (esmini's reading; `--ego scenario` runs)

Datapacks:
  in  `road_users`  {"time_ns", "users": {entity: RoadUser dict}} (scenario_tf.py builds it); an
                    entity that has left the world (absent) keeps its last state
  out `commands`    {"time_ns", "entities": {engine: command}, "weather": {...} | absent}:
                    command = the union of the entity's running actions' targets
                    (`speed`, `lane`, `route`, `trajectory`, `teleport`), every key optional
  out `scenario`    {"time_ns", "t", "done", "ending", "reason", "states": {element: state},
                    "transitions": [[t, type, element, transition]], "running":
                    [[action, actor, kind]], "not_applied": [[t, actor, kind, action]]
                    (actions on the ego the stack drives: not applied, reported), "file"}
  out `route`       {"points": [[x, y], ...], "length"} (the ego's route; empty without one)
  out `entities`    {"time_ns", "users": [RoadUser dict, ...]} (id: the entity's name): the
                    entities this engine moves, at the end of the step

The run ends one step after the storyboard ends (or the ego passed its route's end: "ending"),
so that the last commands reach their engines: "done" is set then, and the status function
(status.py) ends the run.

Errors of the storyboard end the run with one line naming the file, the element and its line
(the engine program keeps only the ScenarioError's message)."""

import csv
import math
import os

from nrp_core.engines.python_json import EngineScript

from convoy_scenario.parsed import load_parsed
from convoy_scenario.odr import OdrQuery, world_pose
from convoy_scenario.player import Player, box_collisions
from convoy_scenario.storyboard import ScenarioRuntimeError, Storyboard
from convoy_scenario.tracks import TracksWriter
from convoy_scenario.xmltree import ScenarioError

DRIVEN = "scenario"     # an Entities value: the engine moves the entity itself
MISSING_STATE_S = 1.0   # an entity without a state this long after the start is an error
ROUTE_END_LATERAL_M = 5.0


def read_route(spec, base_dir="."):
    """[[x, y], ...] from a CSV path (columns x, y) or a list."""
    if spec is None or spec == "":
        return []
    if isinstance(spec, str):
        path = spec if os.path.isabs(spec) else os.path.join(base_dir, spec)
        with open(path) as f:
            return [[float(r["x"]), float(r["y"])] for r in csv.DictReader(f)]
    return [[float(p[0]), float(p[1])] for p in spec]


def polyline_length(points):
    return math.fsum(math.hypot(q[0] - p[0], q[1] - p[1]) for p, q in zip(points, points[1:]))


def past_route_end(points, x, y):
    """True when (x, y) is past the route's last point along its last segment (within
    ROUTE_END_LATERAL_M of its line) or within 1 m of it."""
    if len(points) < 2:
        return False
    (px, py), (ex, ey) = points[-2], points[-1]
    dx, dy = ex - px, ey - py
    n = math.hypot(dx, dy)
    rx, ry = x - ex, y - ey
    if math.hypot(rx, ry) <= 1.0:
        return True
    return n > 0 and (rx * dx + ry * dy) / n >= 0 and abs(rx * dy - ry * dx) / n <= ROUTE_END_LATERAL_M


def parse_entities(entities, scenario):
    """{entity: (engine, state datapack, command datapack or None)}; (None, None, None) for
    the entities the engine moves itself ("scenario")."""
    names = [e.name for e in scenario.entities]
    out = {}
    for name in names:
        spec = (entities or {}).get(name, name)
        if spec == DRIVEN:
            out[name] = (None, None, None)
        elif "/" in spec:
            engine, dp = spec.split("/", 1)
            out[name] = (engine, dp, None)
        else:
            out[name] = (spec, "state", "command")
    for name in entities or {}:
        if name not in names:
            raise ScenarioError("%s: Entities: no entity %r in the scenario (entities: %s)" % (
                os.path.basename(scenario.path), name, ", ".join(names)))
    return out


class Commander:
    """Turns the storyboard's step results into the road users' commands (the contract of
    vehicle_agent / pedestrian_agent's CommandDataPack) and the weather engine's control."""

    def __init__(self, entities, ego, odr):
        self.entities, self.ego, self.odr = entities, ego, odr
        self.routes = {}   # entity -> positions of its last AssignRouteAction (kept)

    def _pose(self, position):
        return world_pose(self.odr, position)

    def _route_positions(self, target):
        pts = []
        for w in target["waypoints"]:
            x, y, _ = self._pose(w["position"])
            pts.append([x, y])
        return pts

    def idle(self, time_ns):
        """Commands without running actions: the kept routes only."""
        out = {}
        for name, (engine, _, command_dp) in sorted(self.entities.items()):
            if command_dp is None or name == self.ego:
                continue
            cmd = {"time_ns": time_ns}
            if name in self.routes:
                cmd["route"] = {"positions": self.routes[name]}
            out[engine] = cmd
        return out

    def _commanded(self, name):
        return self.entities.get(name, (None, None, None))[2] is not None

    def commands(self, result, time_ns):
        """(commands by engine, weather control or None) for a StepResult."""
        per = {}
        weather = None
        for c in result.started:
            if c.kind == "EnvironmentAction" and not c.action.startswith("Init["):
                weather = dict(c.target["weather"])
            if c.actor is not None and not self._commanded(c.actor):
                continue
            if c.kind == "AssignRouteAction" and c.actor is not None:
                self.routes[c.actor] = self._route_positions(c.target)
            if c.kind == "TeleportAction" and c.actor is not None and not c.action.startswith("Init["):
                x, y, yaw = self._pose(c.target["position"])
                per.setdefault(c.actor, {})["teleport"] = {"x": x, "y": y, "yaw": yaw}
        for c in result.running:
            if c.actor is None or not self._commanded(c.actor):
                continue
            cmd = per.setdefault(c.actor, {})
            tg = c.target
            if c.kind == "SpeedAction":
                cmd["speed"] = {k: tg[k] for k in ("speed", "target_speed", "acceleration")}
            elif c.kind == "LaneChangeAction":
                cmd["lane"] = {"road": None if tg["road"] is None else str(tg["road"]),
                               "lane": int(tg["lane"]),
                               "from_lane": None if tg["from_lane"] is None else int(tg["from_lane"]),
                               "offset": tg["offset"], "progress": tg["progress"]}
            elif c.kind == "FollowTrajectoryAction":
                if "x" in tg:
                    cmd["trajectory"] = {k: tg[k] for k in ("x", "y", "yaw", "speed")}
                else:
                    cmd["trajectory"] = {"polyline": [[p[0], p[1]] for p in tg["vertices"]],
                                         "length": tg["length"]}
        out = {}
        for name, (engine, _, command_dp) in sorted(self.entities.items()):
            if command_dp is None or name == self.ego:
                continue
            cmd = {"time_ns": time_ns}
            if name in self.routes:
                cmd["route"] = {"positions": self.routes[name]}
            cmd.update(per.get(name, {}))
            out[engine] = cmd
        return out, weather


ROAD_USER_CATEGORY = {"car": "car", "van": "car", "truck": "truck", "trailer": "truck",
                      "semitrailer": "truck", "bus": "bus", "tram": "bus", "train": "bus",
                      "bicycle": "cyclist", "motorbike": "cyclist"}


def player_road_user(st, entity):
    """The RoadUser dict (proto field names) of a player-driven entity."""
    if entity.kind == "pedestrian":
        category = "pedestrian"
    elif entity.kind == "vehicle":
        category = ROAD_USER_CATEGORY.get(entity.object.category, "car")
    else:
        category = "object"
    u = {"id": st.name, "category": category, "x": st.x, "y": st.y, "z": st.z, "yaw": st.h,
         "speed": st.speed, "vx": st.vx, "vy": st.vy, "length": st.length, "width": st.width,
         "height": entity.object.bounding_box.height, "length_offset": st.length_offset}
    if st.road is not None:
        u.update(road=st.road, lane=st.lane, s=st.s, t=st.road_t)
    return u


def state_dict(u):
    """A RoadUser dict (proto field names) as the storyboard's world state."""
    d = {k: float(u.get(k, 0.0)) for k in ("x", "y", "z", "yaw", "speed", "vx", "vy")}
    for k in ("length", "width", "length_offset"):
        if u.get(k):
            d[k] = float(u[k])
    if u.get("road"):
        d["road"] = str(u["road"])
        d["lane"] = int(u.get("lane", 0))
        d["s"] = float(u.get("s", 0.0))
        d["t"] = float(u.get("t", 0.0))
    return d


class Script(EngineScript):
    def initialize(self):
        cfg = self._config
        self.file = cfg["ScenarioFile"]
        self.base = os.path.basename(self.file)
        self.scenario = load_parsed(cfg.get("ParsedScenario"), self.file, cfg.get("Parameters"))
        self.entities = parse_entities(cfg.get("Entities"), self.scenario)
        self.ego = cfg.get("EgoName", "Ego")
        xodr = cfg.get("Map") or self.scenario.logic_file
        self.odr = OdrQuery(xodr) if xodr else None
        self.commander = Commander(self.entities, self.ego, self.odr)
        self.player = self._player(cfg, xodr)
        self.board = Storyboard(
            self.scenario, end_on_complete=not cfg.get("StopTriggerOnly", False),
            resolve_position=self.player.resolve_xy if self.player is not None else None)
        if self.player is not None and xodr:
            self.board.driving_lanes = self.player.driving_lanes
        self.route = read_route(cfg.get("EgoRoute"), os.path.dirname(self.file))
        self.end_at_route_end = bool(cfg.get("EndAtRouteEnd", True)) and len(self.route) >= 2
        self.end_on_complete = bool(cfg.get("EndOnComplete", True))
        self.board_complete = False
        self.done = False
        self.ending = False   # ended at the last step: done at the next
        self.reason = ""
        self.missing_since = None
        self.last_seen = {}   # entity -> its last state (kept for road users that left)
        self.not_applied = []  # [t, actor, kind, action] aimed at an entity nothing here moves
        self.tracks = TracksWriter.in_run_dir()
        for dp in ("road_users", "commands", "scenario", "route", "entities"):
            self._registerDataPack(dp)
        self._setDataPack("commands", {"time_ns": 0, "entities": {}})
        self._setDataPack("scenario", {"time_ns": 0, "t": 0.0, "done": False, "reason": "",
                                       "states": {}, "transitions": [], "running": [],
                                       "file": self.base})
        self._setDataPack("route", {"points": self.route, "length": polyline_length(self.route)})
        self._publish_entities()
        print("scenario engine: %s, entities %s, ego %s, route %.1f m" % (
            self.base, ", ".join("%s=%s" % (k, v[0]) for k, v in sorted(self.entities.items())),
            self.ego, polyline_length(self.route)), flush=True)

    def _player(self, cfg, xodr):
        driven = [n for n, (engine, _, _) in self.entities.items() if engine is None]
        if not driven and not xodr:
            return None
        from convoy_scenario.player_state import NoRoads
        from convoy_scenario.roads import RoadMap
        self.roads = RoadMap.open(xodr) if xodr else NoRoads()
        return Player(self.scenario, self.roads, driven)

    def _publish_entities(self):
        users = []
        if self.player is not None:
            for name, st in sorted(self.player.states.items()):
                if st.placed:
                    users.append(player_road_user(st, self.scenario.entity(name)))
        self._setDataPack("entities", {"time_ns": self._time_ns, "users": users})

    def _world(self):
        d = self._getDataPack("road_users") or {}
        users = d.get("users") or {}
        world = self.player.world() if self.player is not None else {}
        for name in self.entities:
            if self.player is not None and self.player.controls(name):
                continue
            u = users.get(name)
            if u is None or u.get("absent"):
                if name in self.last_seen:   # left the world (its route ended): its last state
                    world[name] = self.last_seen[name]
                continue
            s = state_dict(u)
            if "road" not in s and self.odr is not None:
                loc = self.odr.locate(s["x"], s["y"], s["yaw"])
                if loc is not None:
                    s.update(road=str(loc["road"]), lane=int(loc["lane"]), s=loc["s"],
                             t=loc["road_t"])
            self._derive(name, s)
            world[name] = s
            self.last_seen[name] = s
        if len(world) > (len(self.player.states) if self.player is not None else 0):
            touching = box_collisions(world)
            for name, s in world.items():
                s["collisions"] = touching.get(name, [])
        return world

    def _derive(self, name, s):
        """What conditions need beyond a RoadUser, for an entity the engine does not move:
        offroad (no road under it), odometer, acceleration."""
        s.setdefault("offroad", "road" not in s)
        s.setdefault("end_of_road", False)
        prev = self.last_seen.get(name)
        dt = getattr(self, "_timestep_s", 0.0)
        if prev is None or dt <= 0:
            s["odometer"], s["ax"], s["ay"] = 0.0, 0.0, 0.0
            return
        s["odometer"] = prev.get("odometer", 0.0) + math.hypot(s["x"] - prev["x"], s["y"] - prev["y"])
        s["ax"] = (s.get("vx", 0.0) - prev.get("vx", 0.0)) / dt
        s["ay"] = (s.get("vy", 0.0) - prev.get("vy", 0.0)) / dt

    def runLoop(self, timestep_ns):
        # the step runs from t to t + timestep: the storyboard sees the states at its start
        # (the engine's clock is already at its end)
        t = (self._time_ns - timestep_ns) * 1e-9
        self._timestep_s = timestep_ns * 1e-9
        if self.done:
            return
        if self.board_complete and not self.ending:
            self._after_complete(t)
            return
        if self.ending:
            # one step after the end, so that the last step's commands reached their engines
            self.done = True
            self._setDataPack("commands", {"time_ns": self._time_ns, "entities": {}})
            self._setDataPack("scenario", dict(self._getDataPack("scenario"), time_ns=self._time_ns,
                                               t=t, done=True, transitions=[], running=[]))
            print("scenario %s done at t=%.2f (%s)" % (self.base, t, self.reason), flush=True)
            return
        world = self._world()
        missing = [n for n in sorted(self.entities) if n not in world]
        if missing:
            if self.missing_since is None:
                self.missing_since = t
            if t - self.missing_since >= MISSING_STATE_S:
                raise ScenarioError("%s: no state of entit%s %s for %.1f s (Entities maps them to %s)" % (
                    self.base, "y" if len(missing) == 1 else "ies", ", ".join(missing),
                    t - self.missing_since, ", ".join(
                        "/".join(x for x in self.entities[n][:2]) for n in missing)))
            return
        if self.tracks is not None:
            self.tracks.step(t, world)
        if self.player is not None:
            self.player.observe(world)
        try:
            result = self.board.step(t, world)
        except ScenarioRuntimeError as e:
            raise ScenarioError("%s: %s" % (self.base, e)) from None
        if self.player is not None:
            self.player.advance(result, t, timestep_ns * 1e-9)
            self._publish_entities()
        commands, weather = self.commander.commands(result, self._time_ns)
        out = {"time_ns": self._time_ns, "entities": commands}
        if weather is not None:
            out["weather"] = weather
        self._setDataPack("commands", out)
        stopped = any(tr.element_type == "storyboard" and tr.transition == "stopTransition"
                      for tr in result.transitions)
        if result.done and (stopped or self.end_on_complete):
            self.ending, self.reason = True, "stop_trigger" if stopped else "storyboard_complete"
        elif result.done and not self.board_complete:
            self.board_complete = True
            print("scenario %s: storyboard complete at t=%.2f; the run goes on to the ego's route "
                  "end or the time limit" % (self.base, t), flush=True)
        elif self.end_at_route_end and self.ego in world and \
                past_route_end(self.route, world[self.ego]["x"], world[self.ego]["y"]):
            self.ending, self.reason = True, "route_end"
        self._setDataPack("scenario", {
            "time_ns": self._time_ns, "t": t, "done": False, "ending": self.ending, "reason": self.reason,
            "states": dict([("Storyboard", self.board.root.state)] + [
                (path, el.state) for (_, path), el in sorted(self.board.elements.items())]),
            "transitions": [[tr.time, tr.element_type, tr.element, tr.transition]
                            for tr in result.transitions],
            "running": [[c.action, c.actor, c.kind] for c in result.running],
            "not_applied": self.not_applied,
            "file": self.base})
        for tr in result.transitions:
            print("t=%.2f %s %s %s" % (tr.time, tr.element_type, tr.element, tr.transition), flush=True)
        self._report_not_applied(t, result)

    MOVING_KINDS = ("SpeedAction", "LaneChangeAction", "LaneOffsetAction", "TeleportAction",
                    "FollowTrajectoryAction", "LongitudinalDistanceAction", "LateralDistanceAction",
                    "SynchronizeAction", "SpeedProfileAction", "AcquirePositionAction",
                    "AssignRouteAction")

    def _report_not_applied(self, t, result):
        """Actions that would move an entity no engine here moves by them (the ego, driven by
        the stack under test): said once each, and listed in the `scenario` datapack's
        `not_applied` (docs/scenarios.md, "Two ego modes")."""
        for c in result.started:
            if c.actor is None or c.kind not in self.MOVING_KINDS:
                continue
            if (self.player is not None and self.player.controls(c.actor)) or \
                    self.commander._commanded(c.actor) or c.action.startswith("Init["):
                continue
            self.not_applied.append([round(t, 3), c.actor, c.kind, c.action])
            print("scenario %s: t=%.2f: %s %s on %s is not applied: the stack under test drives "
                  "it" % (self.base, t, c.kind, c.action, c.actor), flush=True)

    def _after_complete(self, t):
        """The storyboard is complete but the run goes on: no commands (the agents' own AI), the
        route's end still ends it."""
        world = self._world()
        if self.tracks is not None:
            self.tracks.step(t, world)
        if self.player is not None:   # no actions left: the entities keep their speeds
            from convoy_scenario.storyboard import StepResult
            self.player.advance(StepResult(t), t, self._timestep_s)
            self._publish_entities()
        self._setDataPack("commands", {"time_ns": self._time_ns, "entities": self.commander.idle(self._time_ns)})
        if self.end_at_route_end and self.ego in world and \
                past_route_end(self.route, world[self.ego]["x"], world[self.ego]["y"]):
            self.ending, self.reason = True, "route_end"
        self._setDataPack("scenario", dict(self._getDataPack("scenario"), time_ns=self._time_ns, t=t,
                                           ending=self.ending, reason=self.reason, transitions=[],
                                           running=[]))

    def reset(self):
        """NRP-Core's reset (convoy_gym's scenario episodes): the storyboard, the player and
        every state again from the start, as after initialize()."""
        self.shutdown()
        self._datapacks = {}
        self.initialize()

    def shutdown(self):
        if getattr(self, "odr", None) is not None:
            self.odr.close()
        if getattr(self, "tracks", None) is not None:
            self.tracks.close()
