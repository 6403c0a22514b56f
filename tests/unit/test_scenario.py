"""Unit tests of convoy_scenario (docs/scenarios.md): the .xosc reader on the fixtures of
tests/unit/scenarios/ and on variants made from them, the storyboard executor against
hand-computed times and targets, and the weather mapping.

Run: cd tests/unit && PYTHONPATH=../../python /usr/bin/python3 -m unittest -v test_scenario
(ctest: py_scenario)."""

import math
import os
import sys
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
PYTHON_DIR = os.path.join(os.path.dirname(os.path.dirname(HERE)), "python")
if PYTHON_DIR not in sys.path:
    sys.path.insert(0, PYTHON_DIR)

from convoy_scenario import (ScenarioError, ScenarioRuntimeError, Storyboard,  # noqa: E402
                             environment_to_weather, load, loads, schedule_entry,
                             weather_config)
from convoy_scenario import actions as act  # noqa: E402
from convoy_scenario import geometry as geo  # noqa: E402
from convoy_scenario import model as m  # noqa: E402
from convoy_scenario import params  # noqa: E402
from convoy_scenario import weather as wx  # noqa: E402

SCENARIOS = os.path.join(HERE, "scenarios")


def fixture(name):
    return os.path.join(SCENARIOS, name)


def text_of(name):
    with open(fixture(name)) as f:
        return f.read()


def load_variant(name, old, new, parameters=None):
    """The fixture name with old replaced by new (which must occur), read as if it were the
    fixture itself."""
    text = text_of(name)
    assert old in text, old
    return loads(text.replace(old, new, 1), fixture(name), parameters)


# --- a kinematic world for whole scenarios ---------------------------------------------------

def lane_y(lane):
    """Centre of a lane of straight.xodr (3.5 m lanes along +x)."""
    lane = int(lane)
    return -(abs(lane) - 0.5) * 3.5 if lane < 0 else (lane - 0.5) * 3.5


class KinematicWorld:
    """Entities that do what the actions say: teleports, commanded speeds, lane changes by
    progress, timed trajectories' poses, untimed trajectories walked at the entity's speed;
    otherwise straight along the heading. Road coordinates: s = x, t = y."""

    def __init__(self, names, dt=0.1):
        self.dt = dt
        self.state = {n: {"x": 0.0, "y": 0.0, "yaw": 0.0, "speed": 0.0, "lane": None}
                      for n in names}
        self.paths = {}

    def world(self):
        out = {}
        for n, s in self.state.items():
            d = dict(s, road="1", s=s["x"], t=s["y"])
            if d["lane"] is None:
                del d["lane"]
            out[n] = d
        return out

    def apply(self, result):
        posed = set()
        for c in result.running:
            s, tg = self.state.get(c.actor), c.target
            if c.kind == "TeleportAction":
                p = tg["position"]
                if p["type"] == "lane":
                    s.update(x=p["s"], y=lane_y(p["lane"]) + p["offset"], lane=p["lane"])
                else:
                    s.update(x=p["x"], y=p["y"], yaw=p["h"] or 0.0)
            elif c.kind == "SpeedAction":
                s["speed"] = tg["speed"]
            elif c.kind == "LaneChangeAction":
                y0, y1 = lane_y(tg["from_lane"]), lane_y(tg["lane"])
                s["y"] = y0 + (y1 - y0) * tg["progress"] + tg["offset"]
                s["lane"] = tg["lane"] if tg["progress"] >= 0.5 else tg["from_lane"]
            elif c.kind == "FollowTrajectoryAction":
                if "x" in tg:
                    s.update(x=tg["x"], y=tg["y"], yaw=tg["yaw"], speed=tg["speed"])
                    posed.add(c.actor)
                else:
                    self.paths[c.actor] = tg["vertices"][-1]
        for n, s in self.state.items():
            if n in posed:
                continue
            if n in self.paths:
                gx, gy = self.paths[n][0], self.paths[n][1]
                d = math.hypot(gx - s["x"], gy - s["y"])
                if d > 0:
                    s["yaw"] = math.atan2(gy - s["y"], gx - s["x"])
                    step = min(d, s["speed"] * self.dt)
                    s["x"] += step * (gx - s["x"]) / d
                    s["y"] += step * (gy - s["y"]) / d
                continue
            s["x"] += s["speed"] * math.cos(s["yaw"]) * self.dt
            s["y"] += s["speed"] * math.sin(s["yaw"]) * self.dt


def simulate(scenario, names, t_end, dt=0.1):
    board, world = Storyboard(scenario), KinematicWorld(names, dt)
    results, k = [], 0
    while k * dt <= t_end + 1e-9:
        r = board.step(round(k * dt, 9), world.world())
        results.append(r)
        world.apply(r)
        k += 1
        if r.done:
            break
    return results, world


def transitions(results, element=None, kind=None):
    """[(time, last name of the element, transition, from, to)], optionally filtered."""
    out = []
    for r in results:
        for tr in r.transitions:
            name = tr.element.split("::")[-1]
            if (element is None or name == element) and (kind is None or tr.transition == kind):
                out.append((round(tr.time, 6), name, tr.transition, tr.from_state, tr.to_state))
    return out


def command(results, t, action_suffix, actor=None):
    for r in results:
        if abs(r.time - t) < 1e-9:
            for c in r.running:
                if c.action.endswith(action_suffix) and (actor is None or c.actor == actor):
                    return c
    raise AssertionError("no command %s at %g" % (action_suffix, t))


# --- generated scenarios for the executor's rules ----------------------------------------------

def speed_cond(edge="none", delay=0, rule="greaterThan", value=1, entity="A", name="c"):
    return ('<Condition name="%s" delay="%g" conditionEdge="%s"><ByEntityCondition>'
            '<TriggeringEntities triggeringEntitiesRule="any"><EntityRef entityRef="%s"/>'
            '</TriggeringEntities><EntityCondition><SpeedCondition value="%g" rule="%s"/>'
            '</EntityCondition></ByEntityCondition></Condition>'
            % (name, delay, edge, entity, value, rule))


def time_cond(value, rule="greaterOrEqual", edge="none", delay=0):
    return ('<Condition name="t" delay="%g" conditionEdge="%s"><ByValueCondition>'
            '<SimulationTimeCondition value="%g" rule="%s"/></ByValueCondition></Condition>'
            % (delay, edge, value, rule))


def state_cond(etype, ref, state, edge="none"):
    return ('<Condition name="s" delay="0" conditionEdge="%s"><ByValueCondition>'
            '<StoryboardElementStateCondition storyboardElementType="%s" '
            'storyboardElementRef="%s" state="%s"/></ByValueCondition></Condition>'
            % (edge, etype, ref, state))


def trigger(*groups, tag="StartTrigger"):
    """Each argument is a ConditionGroup: a condition string or a tuple of them."""
    body = "".join("<ConditionGroup>%s</ConditionGroup>" % (
        "".join(g) if isinstance(g, tuple) else g) for g in groups)
    return "<%s>%s</%s>" % (tag, body, tag)


TELEPORT = ('<PrivateAction><TeleportAction><Position><WorldPosition x="1" y="2"/></Position>'
            '</TeleportAction></PrivateAction>')


def speed_action(target, rate=1.0):
    return ('<PrivateAction><LongitudinalAction><SpeedAction><SpeedActionDynamics '
            'dynamicsShape="linear" dynamicsDimension="rate" value="%g"/><SpeedActionTarget>'
            '<AbsoluteTargetSpeed value="%g"/></SpeedActionTarget></SpeedAction>'
            '</LongitudinalAction></PrivateAction>' % (rate, target))


def event(name, start=None, priority="overwrite", count=1, action=TELEPORT):
    return ('<Event name="%s" priority="%s" maximumExecutionCount="%d"><Action name="%s_action">'
            '%s</Action>%s</Event>' % (name, priority, count, name, action, start or ""))


def scenario(events, act_start="", act_stop="", board_stop="", group_count=1, extra_acts=""):
    vehicle = ('<Vehicle name="v" vehicleCategory="car"><BoundingBox><Center x="0" y="0" z="0.7"/>'
               '<Dimensions width="2" length="4" height="1.4"/></BoundingBox><Performance '
               'maxSpeed="50" maxAcceleration="5" maxDeceleration="9"/></Vehicle>')
    text = ('<?xml version="1.0"?><OpenSCENARIO><FileHeader revMajor="1" revMinor="1" date="" '
            'description="generated" author="test"/><Entities>'
            '<ScenarioObject name="A">%s</ScenarioObject><ScenarioObject name="B">%s'
            '</ScenarioObject></Entities><Storyboard><Init><Actions/></Init>'
            '<Story name="S"><Act name="Act">'
            '<ManeuverGroup name="G" maximumExecutionCount="%d"><Actors '
            'selectTriggeringEntities="false"><EntityRef entityRef="A"/></Actors>'
            '<Maneuver name="M">%s</Maneuver></ManeuverGroup>%s%s</Act>%s</Story>%s</Storyboard>'
            '</OpenSCENARIO>' % (vehicle, vehicle, group_count, "".join(events), act_start,
                                 act_stop, extra_acts, board_stop))
    return loads(text, os.path.join(SCENARIOS, "generated.xosc"))


def still(speed_a=0.0, ax=0.0, ay=0.0, **b):
    """A world with A at (ax, ay) and B (default at (50, 0)) at rest, headings 0."""
    return {"A": {"x": ax, "y": ay, "yaw": 0.0, "speed": speed_a},
            "B": dict({"x": 50.0, "y": 0.0, "yaw": 0.0, "speed": 0.0}, **b)}


def run_worlds(sc, worlds, dt=0.1):
    board = Storyboard(sc)
    return [board.step(round(k * dt, 9), w) for k, w in enumerate(worlds)]


def start_times(results, name):
    return [tr[0] for tr in transitions(results, name, "startTransition")]


# --- reading -----------------------------------------------------------------------------------

class Reading(unittest.TestCase):
    def assertMessage(self, message, fn, *args):
        with self.assertRaises(ScenarioError) as e:
            fn(*args)
        self.assertEqual(str(e.exception), message)

    def test_cut_in(self):
        sc = load(fixture("cut_in.xosc"))
        self.assertEqual((sc.header.rev_major, sc.header.rev_minor, sc.header.description),
                         (1, 1, "cut-in"))
        self.assertEqual(sc.logic_file, fixture("straight.xodr"))
        self.assertEqual([(e.name, e.kind) for e in sc.entities],
                         [("Ego", "vehicle"), ("Cutter", "vehicle")])
        box = sc.entity("Ego").object.bounding_box
        self.assertEqual((box.center, box.length, box.width, box.height),
                         ((1.4, 0.0, 0.75), 4.5, 1.8, 1.5))
        self.assertEqual(sc.init[0], m.InitAction("Ego", m.TeleportAction(
            m.LanePosition("1", "-1", 50.0, 0.0)), "cut_in.xosc:39"))
        self.assertEqual(sc.init[3].spec.target, m.AbsoluteTargetSpeed(25.0))
        ev = sc.stories[0].acts[0].groups[0].maneuvers[0].events
        self.assertEqual(ev[0].path, "CutInStory::CutInAct::CutterGroup::CutInManeuver::CutInEvent")
        lc = ev[0].actions[0].spec
        self.assertEqual(lc, m.LaneChangeAction(m.Dynamics("sinusoidal", "time", 3.0),
                                                m.RelativeTargetLane("Ego", 0), 0.0))
        cond = ev[0].start_trigger.groups[0][0]
        self.assertEqual((cond.edge, cond.triggering, cond.test),
                         ("rising", ("Ego",), m.TimeHeadwayCondition("Cutter", 0.4, True,
                                                                      "greaterThan", "entity")))
        state = ev[1].start_trigger.groups[0][0].test
        self.assertEqual(state.element_path, ev[0].path)
        self.assertEqual(ev[1].actions[0].spec.target,
                         m.RelativeTargetSpeed("Ego", 0.0, "delta", False))

    def test_parameters_expressions_and_catalogs(self):
        sc = load(fixture("parameters.xosc"))
        p = dict(sc.parameters)
        self.assertEqual(p, {"SpeedKmh": 72.0, "Lanes": 2, "Model": "sedan", "Animated": True,
                             "Speed": 20.0, "Gap": -8.0, "Start": 25})
        self.assertIsInstance(p["Start"], int)
        self.assertEqual(sc.init[0].spec.position, m.LanePosition("1", "-2", 25.0, -8.0))
        ego = sc.entity("Ego")
        self.assertEqual(ego.object.performance, m.Performance(60.0, 4.0, 9.0))
        self.assertEqual(ego.object.bounding_box.length, 4.65)
        self.assertEqual(ego.catalog, m.CatalogSource(
            "ConvoyVehicles", "sedan", fixture("catalogs/vehicles.xosc"),
            (("Length", 4.65), ("MaxSpeed", 60.0))))
        self.assertEqual(ego.object.properties, (("model", "sedan_red"),))
        self.assertEqual(sc.entity("Bus").object.performance.max_speed, 25.0)
        walker = sc.entity("Walker")
        self.assertEqual((walker.kind, walker.object.mass, walker.object.category),
                         ("pedestrian", 75.0, "pedestrian"))
        group = sc.stories[0].acts[0].groups[0]
        self.assertEqual(group.actors, ("Bus",))  # the Story's $Actor
        spec = group.maneuvers[0].events[0].actions[0].spec
        self.assertEqual(spec, m.SpeedAction(m.Dynamics("linear", "time", 2.5),
                                             m.AbsoluteTargetSpeed(25.0)))  # the Story's $Speed

    def test_parameter_overrides(self):
        sc = load(fixture("parameters.xosc"), {"SpeedKmh": 36, "Animated": False})
        p = dict(sc.parameters)
        self.assertEqual((p["Speed"], p["Gap"], p["Animated"]), (10.0, -3.0, False))
        self.assertEqual(sc.entity("Ego").object.performance.max_speed, 30.0)
        # the bus declares no MaxSpeed: the reference's assignment is refused
        self.assertMessage("parameters.xosc:24: <ParameterAssignment> parameterRef: the entry "
                           "declares no parameter MaxSpeed", load, fixture("parameters.xosc"),
                           {"Model": "bus"})
        with self.assertRaises(ScenarioError) as e:
            load(fixture("parameters.xosc"), {"Speeed": 1})
        self.assertEqual(str(e.exception), "parameters.xosc: parameter override Speeed: the "
                                           "file declares no global parameter Speeed")
        with self.assertRaises(ScenarioError) as e:
            load(fixture("parameters.xosc"), {"Lanes": "two"})
        self.assertEqual(str(e.exception), "parameters.xosc: parameter override Lanes: value: "
                                           "expected an integer, got 'two'")

    def test_trajectory_and_route(self):
        sc = load(fixture("follow_trajectory.xosc"))
        timed = sc.stories[0].acts[0].groups[0].maneuvers[0].events[0].actions[0].spec
        self.assertEqual([(v.position.x, v.position.y, v.time) for v in timed.vertices],
                         [(0.0, 0.0, 0.0), (20.0, 0.0, 2.0), (20.0, 20.0, 4.0)])
        self.assertEqual((timed.timing, timed.following_mode),
                         (m.Timing("relative", 1.0, 0.0), "position"))
        untimed = sc.stories[0].acts[0].groups[0].maneuvers[0].events[1].actions[0].spec
        self.assertEqual((untimed.timing, untimed.following_mode), (None, "follow"))
        route = ('<PrivateAction><RoutingAction><AssignRouteAction><Route name="r" closed="false">'
                 '<Waypoint routeStrategy="shortest"><Position><LanePosition roadId="1" '
                 'laneId="-1" s="5"/></Position></Waypoint><Waypoint routeStrategy="fastest">'
                 '<Position><WorldPosition x="9" y="8"/></Position></Waypoint></Route>'
                 '</AssignRouteAction></RoutingAction></PrivateAction>')
        sc = scenario([event("E", action=route)])
        spec = sc.stories[0].acts[0].groups[0].maneuvers[0].events[0].actions[0].spec
        self.assertEqual(spec, m.AssignRouteAction("r", False, (
            m.Waypoint(m.LanePosition("1", "-1", 5.0), "shortest"),
            m.Waypoint(m.WorldPosition(9.0, 8.0), "fastest"))))

    def test_environment(self):
        sc = load(fixture("environment.xosc"))
        env = sc.init[0].spec.environment
        self.assertEqual(env.time_of_day, (False, "2026-03-01T14:30:00"))
        self.assertEqual(env.weather.precipitation, m.Precipitation("rain", 0.6, None))
        self.assertEqual((env.weather.fog_visual_range, env.weather.cloud_state,
                          env.friction_scale_factor), (200.0, "rainy", 0.6))
        self.assertEqual(env.weather.sun, m.Sun(math.pi, math.pi / 6, 20000.0))


class Expressions(unittest.TestCase):
    def scope(self):
        s = params.Scope()
        s.values.update(a=("double", 2.0), b=("integer", 3), name=("string", "x"))
        return s

    def test_values(self):
        s = self.scope()
        for source, value in (("$a + 2 * $b", 8.0), ("($a + 2) * $b", 12.0),
                              ("-$a - -$b", 1.0), ("10 / 4 - 1", 1.5), ("7 % 4", 3.0),
                              ("-(1 + 2) * -2", 6.0), ("2 * 3e1", 60.0), (".5 + 1.", 1.5),
                              ("pow(2, 10) + sqrt(16) + round(2.5) + floor(-1.5) + ceil(1.2)",
                               1031.0)):
            self.assertEqual(params.evaluate(source, s), value, source)
        self.assertEqual(params.resolve("${250 / 4}", s), 62.5)
        self.assertEqual(params.resolve("$b", s), 3)
        self.assertEqual(params.resolve("plain", s), "plain")

    def test_errors(self):
        s = self.scope()
        for source, message in (
                ("1 / ($b - 3)", "expression ${1 / ($b - 3)}: division by zero"),
                ("$c + 1", "expression ${$c + 1}: unknown parameter $c"),
                ("$name * 2", "expression ${$name * 2}: $name is a string parameter, not a number"),
                ("exp(1)", "expression ${exp(1)}: unknown function 'exp' (round, floor, ceil, sqrt, pow)"),
                ("__import__('os')", "expression ${__import__('os')}: unexpected \"'os')\""),
                ("__import__(1)", "expression ${__import__(1)}: unknown function '__import__' "
                                  "(round, floor, ceil, sqrt, pow)"),
                ("1 +", "expression ${1 +}: unexpected end"),
                ("(1", "expression ${(1}: expected ')'"),
                ("1 2", "expression ${1 2}: unexpected 2.0"),
                ("2 ** 3", "expression ${2 ** 3}: unexpected '*'"),
                ("sqrt(-1)", "expression ${sqrt(-1)}: sqrt of a negative number")):
            with self.assertRaises(params.ParameterError) as e:
                params.evaluate(source, s)
            self.assertEqual(str(e.exception), message, source)

    def test_types(self):
        self.assertEqual(params.convert("7", "integer"), 7)
        self.assertEqual(params.convert(7.0, "unsignedInt"), 7)
        self.assertEqual(params.convert(-2.0, "string"), "-2")
        self.assertEqual(params.convert("false", "boolean"), False)
        for value, ptype in (("7.5", "integer"), (7.5, "int"), ("-1", "unsignedShort"),
                             ("yes", "boolean"), ("1,5", "double"), ("nan", "double")):
            with self.assertRaises(params.ParameterError):
                params.convert(value, ptype)


class BadScenarios(unittest.TestCase):
    def assertMessage(self, message, fn, *args):
        with self.assertRaises(ScenarioError) as e:
            fn(*args)
        self.assertEqual(str(e.exception), message)

    def test_unsupported_element_names_its_line(self):
        self.assertMessage(
            "bad_unsupported.xosc:56: <SynchronizeAction> is not supported in <PrivateAction> "
            "(supported here: LongitudinalAction, LateralAction, RoutingAction, TeleportAction)",
            load, fixture("bad_unsupported.xosc"))

    def test_unknown_parameter(self):
        self.assertMessage("bad_parameter.xosc:33: <AbsoluteTargetSpeed> value: unknown "
                           "parameter $EgoSpeed", load, fixture("bad_parameter.xosc"))

    def test_missing_catalog(self):
        self.assertMessage(
            "bad_catalog.xosc:22: <CatalogReference> catalogName: 'ConvoyVehicles': the catalog "
            "directory %s (bad_catalog.xosc:16) does not exist"
            % os.path.join(SCENARIOS, "no_such_catalogs"), load, fixture("bad_catalog.xosc"))

    def test_variants(self):
        cases = (
            ("cut_in.xosc", '<TimeHeadwayCondition entityRef="Cutter"',
             '<TimeHeadwayCondition entityRef="Cuter"',
             "cut_in.xosc:96: <TimeHeadwayCondition> entityRef: no entity 'Cuter' (entities: "
             "Ego, Cutter)"),
            ("cut_in.xosc", 'value="$Headway" freespace="true"', 'value="$Headway" freespace="maybe"',
             "cut_in.xosc:96: <TimeHeadwayCondition> freespace: expected true or false, got 'maybe'"),
            ("cut_in.xosc", '<ParameterDeclaration name="EgoSpeed" parameterType="double" value="20"/>',
             '<ParameterDeclaration name="EgoSpeed" parameterType="double" value="fast"/>',
             "cut_in.xosc:8: <ParameterDeclaration> value: expected a number, got 'fast'"),
            ("cut_in.xosc", '<AbsoluteTargetSpeed value="$CutterSpeed"/>',
             '<AbsoluteTargetSpeed value="$Headway" unit="kmh"/>',
             "cut_in.xosc:63: <AbsoluteTargetSpeed> attribute unit is not supported (supported: value)"),
            ("cut_in.xosc", 'dynamicsShape="sinusoidal" dynamicsDimension="time" value="3"',
             'dynamicsShape="sinusoidal" dynamicsDimension="rate" value="3"',
             "cut_in.xosc:82: <LaneChangeActionDynamics> dynamicsDimension: rate is not supported "
             "with dynamicsShape sinusoidal (supported: time, distance)"),
            ("cut_in.xosc", 'storyboardElementRef="CutInEvent"', 'storyboardElementRef="CutOut"',
             "cut_in.xosc:122: <StoryboardElementStateCondition> storyboardElementRef: no event "
             "named 'CutOut'"),
            ("cut_in.xosc", '<Event name="SlowDownEvent"', '<Event name="CutInEvent"',
             "cut_in.xosc:105: <Event> name: another event is named "
             "'CutInStory::CutInAct::CutterGroup::CutInManeuver::CutInEvent'"),
            ("cut_in.xosc", 'revMajor="1" revMinor="1"', 'revMajor="2" revMinor="0"',
             "cut_in.xosc:6: <FileHeader> revMajor: only OpenSCENARIO 1.x is supported, got 2"),
            ("cut_in.xosc", 'filepath="straight.xodr"', 'filepath="roads/none.xodr"',
             "cut_in.xosc:13: <LogicFile> filepath: no such file %s"
             % os.path.join(SCENARIOS, "roads", "none.xodr")),
            ("cut_in.xosc", "<Story name=\"CutInStory\">", "<Story name=\"CutInStory\"><Story>",
             "cut_in.xosc:147: not well-formed XML: mismatched tag"),
            ("cut_in.xosc", '<Condition name="CutInDone" delay="0"', '<Condition name="CutInDone" delay="-1"',
             "cut_in.xosc:120: <Condition> delay: must be >= 0, got -1"),
            ("pedestrian_crossing.xosc", '<WorldPosition x="60" y="9"/></Position>\n              </Reach',
             '<LanePosition roadId="1" laneId="1" s="60"/></Position>\n              </Reach',
             "pedestrian_crossing.xosc:112: <LanePosition> is not supported in "
             "ReachPositionCondition (needs the road network): use WorldPosition"),
            ("parameters.xosc", 'entryName="bus"', 'entryName="tram"',
             "parameters.xosc:29: <CatalogReference> entryName: no entry 'tram' in catalog "
             "'ConvoyVehicles' (%s; entries: sedan, bus)" % fixture("catalogs/vehicles.xosc")),
            ("parameters.xosc", 'catalogName="ConvoyPeople"', 'catalogName="People"',
             "parameters.xosc:32: <CatalogReference> catalogName: no catalog named 'People' in "
             "%s, %s, %s, %s" % (fixture("catalogs/people.xosc"), fixture("catalogs/vehicles.xosc"),
                                 fixture("catalogs/people.xosc"), fixture("catalogs/vehicles.xosc"))),
            ("parameters.xosc", 'parameterRef="MaxSpeed"', 'parameterRef="TopSpeed"',
             "parameters.xosc:24: <ParameterAssignment> parameterRef: the entry declares no "
             "parameter TopSpeed"),
            ("follow_trajectory.xosc", '<Vertex time="2">', '<Vertex time="-1">',
             "follow_trajectory.xosc:39: <Vertex> time: -1 comes before the previous vertex's 0"),
            ("environment.xosc", '<Fog visualRange="200"/>', '<Fog visualRange="0"/>',
             "environment.xosc:23: <Fog> visualRange: must be > 0, got 0"),
            ("environment.xosc", '<Actors selectTriggeringEntities="false"/>',
             '<Actors selectTriggeringEntities="true"/>',
             "environment.xosc:35: <Actors> selectTriggeringEntities: true is not supported"),
        )
        for name, old, new, message in cases:
            with self.subTest(new=new):
                self.assertMessage(message, load_variant, name, old, new)

    def test_catalog_entries_are_checked_too(self):
        import shutil
        import tempfile
        tmp = tempfile.mkdtemp()
        self.addCleanup(shutil.rmtree, tmp)
        shutil.copy(fixture("straight.xodr"), tmp)
        os.mkdir(os.path.join(tmp, "catalogs"))
        shutil.copy(fixture("catalogs/people.xosc"), os.path.join(tmp, "catalogs"))
        with open(fixture("catalogs/vehicles.xosc")) as f:
            text = f.read().replace('<TrailerHitch dx="1"/>', "")
        with open(os.path.join(tmp, "catalogs", "vehicles.xosc"), "w") as f:
            f.write(text.replace("<Axles>", '<TrailerHitch dx="-1"/><Axles>', 1))
        with open(os.path.join(tmp, "s.xosc"), "w") as f:
            f.write(text_of("parameters.xosc"))
        self.assertMessage("vehicles.xosc:16: <TrailerHitch> is not supported in <Vehicle> "
                           "(supported here: ParameterDeclarations, BoundingBox, Performance, "
                           "Axles, Properties)", load, os.path.join(tmp, "s.xosc"))
