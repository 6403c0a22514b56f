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
        self.assertTrue(str(e.exception).startswith(
            "parameters.xosc: parameter override Speeed: the file declares no global parameter "
            "Speeed (it declares: "), str(e.exception))
        self.assertIn("Speed", str(e.exception).split("it declares: ")[1])
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
            "bad_unsupported.xosc:56: <UserDefinedAction> is not supported in <PrivateAction> "
            "(supported here: LongitudinalAction, LateralAction, VisibilityAction, "
            "SynchronizeAction, ActivateControllerAction, ControllerAction, TeleportAction, "
            "RoutingAction, AppearanceAction, TrailerAction)",
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
             "cut_in.xosc:122: <StoryboardElementStateCondition> storyboardElementRef: "
             "'CutInEvent' names 2 events (CutInStory::CutInAct::CutterGroup::CutInManeuver::"
             "CutInEvent, CutInStory::CutInAct::CutterGroup::CutInManeuver::CutInEvent#2): "
             "give its path"),
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
             '<RelativeLanePosition entityRef="Walker" dLane="1"/></Position>\n              </Reach',
             "pedestrian_crossing.xosc:112: <RelativeLanePosition> needs exactly one of the "
             "attributes ds and dsLane"),
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
             '<Actors selectTriggeringEntities="maybe"/>',
             "environment.xosc:35: <Actors> selectTriggeringEntities: expected true or false, "
             "got 'maybe'"),
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
            f.write(text.replace("<Axles>", '<Wheels count="4"/><Axles>', 1))
        with open(os.path.join(tmp, "s.xosc"), "w") as f:
            f.write(text_of("parameters.xosc"))
        self.assertMessage("vehicles.xosc:16: <Wheels> is not supported in <Vehicle> "
                           "(supported here: ParameterDeclarations, BoundingBox, Performance, "
                           "Axles, Properties, TrailerHitch, TrailerCoupler, Trailer)",
                           load, os.path.join(tmp, "s.xosc"))


# --- executing ---------------------------------------------------------------------------------

class WholeScenarios(unittest.TestCase):
    def test_cut_in(self):
        results, world = simulate(load(fixture("cut_in.xosc"), {"Headway": 0.41}),
                                  ["Ego", "Cutter"], 30)
        # the cutter's rear (x - 0.85) is 0.41 s x 20 m/s ahead of the ego's front (x + 3.65)
        # when (30 + 25 t - 0.85) - (50 + 20 t + 3.65) > 8.2: t > 6.54
        self.assertEqual(transitions(results, "CutInEvent"),
                         [(6.6, "CutInEvent", "startTransition", "standbyState", "runningState"),
                          (9.6, "CutInEvent", "endTransition", "runningState", "completeState")])
        mid = command(results, 8.1, "CutInAction")
        self.assertEqual((mid.target["lane"], mid.target["from_lane"]), ("-1", "-2"))
        self.assertAlmostEqual(mid.target["progress"], 0.5, places=12)
        # one step after the endTransition; 25 -> 20 m/s at 2 m/s^2 takes 2.5 s; the world
        # has the speed one step after the command
        self.assertEqual(start_times(results, "SlowDownEvent"), [9.7])
        self.assertAlmostEqual(command(results, 10.7, "SlowDownAction").target["speed"], 23.0)
        self.assertEqual(transitions(results, "Storyboard"),
                         [(0.0, "Storyboard", "startTransition", "standbyState", "runningState"),
                          (12.3, "Storyboard", "endTransition", "runningState", "completeState")])
        self.assertEqual((world.state["Cutter"]["lane"], world.state["Cutter"]["speed"]),
                         ("-1", 20.0))
        init = [(c.action, c.actor, c.kind) for c in results[0].started]
        self.assertEqual(init, [("Init[0]", "Ego", "TeleportAction"),
                                ("Init[1]", "Ego", "SpeedAction"),
                                ("Init[2]", "Cutter", "TeleportAction"),
                                ("Init[3]", "Cutter", "SpeedAction")])

    def test_determinism(self):
        def trace():
            results, _ = simulate(load(fixture("cut_in.xosc")), ["Ego", "Cutter"], 30)
            return [(r.time, r.transitions, [(c.action, c.actor, c.target) for c in r.running],
                     r.ended) for r in results]
        self.assertEqual(trace(), trace())

    def test_pedestrian_crossing(self):
        results, world = simulate(load(fixture("pedestrian_crossing.xosc")), ["Ego", "Walker"], 40)
        # |(10 t, -1.75) - (60, -9)| < 30 from t > 3.089
        self.assertEqual(start_times(results, "CrossEvent"), [3.1])
        self.assertAlmostEqual(command(results, 3.6, "WalkSpeed").target["speed"], 0.75)
        path = command(results, 3.1, "WalkPath").target
        self.assertEqual(path, {"vertices": [[60.0, -9.0, 0.0], [60.0, 9.0, 0.0]], "length": 18.0})
        stop = transitions(results, kind="stopTransition")
        t_stop = stop[0][0]
        self.assertEqual([s[1:] for s in stop], [
            ("Storyboard", "stopTransition", "runningState", "completeState"),
            ("CrossingStory", "stopTransition", "runningState", "completeState"),
            ("CrossingAct", "stopTransition", "runningState", "completeState"),
            ("WalkerGroup", "stopTransition", "runningState", "completeState"),
            ("CrossManeuver", "stopTransition", "runningState", "completeState"),
            ("CrossEvent", "stopTransition", "runningState", "completeState"),
            ("WalkPath", "stopTransition", "runningState", "completeState")])
        # commanded 0, 0.15, ..., 1.5 m/s at 3.1 ... 4.1 s: 0.825 m walked by 4.2 s, then
        # 0.15 m a step; y >= 8 (within 1 m of the far sidewalk) after 17 m: 108 steps later
        self.assertEqual(t_stop, 15.0)
        self.assertTrue(results[-1].done)
        self.assertEqual(results[-1].ended, [(
            "CrossingStory::CrossingAct::WalkerGroup::CrossManeuver::CrossEvent::WalkPath",
            "Walker", "stop")])

    def test_lead_brake(self):
        results, world = simulate(load(fixture("lead_brake.xosc")), ["Ego", "Lead"], 40)
        # freespace gap 95 - 10 t closing at 10 m/s: TTC 9.5 - t < 7.95 from t > 1.55
        self.assertEqual(start_times(results, "BrakeEvent"), [1.6])
        self.assertAlmostEqual(command(results, 2.1, "Brake").target["speed"], 18.0)
        self.assertEqual(command(results, 2.1, "Brake").target["acceleration"], -4.0)
        self.assertEqual(transitions(results, "Brake", "endTransition")[0][0], 6.7)
        # SpeedCondition equalTo 0 rises at 6.7; delay 2
        self.assertEqual(start_times(results, "DriveOffEvent"), [8.7])
        self.assertEqual(world.state["Lead"]["speed"], 20.0)

    def test_follow_trajectory(self):
        board = Storyboard(load(fixture("follow_trajectory.xosc")))
        car = {"x": 0.0, "y": 0.0, "yaw": 0.0, "speed": 0.0}
        seen = {}
        for k in range(0, 61):
            t = round(k * 0.1, 9)
            r = board.step(t, {"Car": dict(car)})
            for c in r.running:
                seen[(t, c.action.split("::")[-1])] = c.target
            for tr in r.transitions:
                seen[(t, tr.element.split("::")[-1], tr.transition)] = True
        self.assertIn((1.0, "Timed", "startTransition"), seen)
        at2 = seen[(2.0, "Timed")]
        self.assertEqual((at2["x"], at2["y"], at2["yaw"], at2["speed"]), (10.0, 0.0, 0.0, 10.0))
        at4 = seen[(4.0, "Timed")]
        self.assertEqual((at4["x"], at4["y"], at4["yaw"]), (20.0, 10.0, math.pi / 2))
        self.assertIn((5.0, "Timed", "endTransition"), seen)
        self.assertEqual((seen[(5.0, "Timed")]["x"], seen[(5.0, "Timed")]["speed"]), (20.0, 0.0))
        self.assertIn((5.1, "Back", "startTransition"), seen)  # rising edge, one step later
        self.assertNotIn((6.0, "Back", "endTransition"), seen)   # the car has not moved
        # untimed: ends within 0.5 m of the last vertex, or past it along the last segment
        r = board.step(6.1, {"Car": {"x": 0.4, "y": 20.2, "yaw": math.pi, "speed": 3.0}})
        self.assertEqual([tr.element.split("::")[-1] for tr in r.transitions
                          if tr.transition == "endTransition"][:1], ["Back"])

    def test_timed_trajectory_absolute_and_heading(self):
        traj = m.FollowTrajectoryAction("t", (
            m.Vertex(m.WorldPosition(0, 0, 0, 0.0), 10.0),
            m.Vertex(m.WorldPosition(10, 0, 0, 3.0), 12.0),
            m.Vertex(m.WorldPosition(10, 0, 0, -3.0), 13.0)), m.Timing("absolute", 2.0, -15.0))

        class Env:
            def body(self, name, user):
                return None
        run = act.make_run("a", traj, "Car", 1.0, Env())
        self.assertEqual(run.times, [5.0, 9.0, 11.0])
        target, done = run.update(7.0, Env())
        self.assertEqual((target["x"], target["yaw"], target["speed"], done), (5.0, 1.5, 2.5, False))
        target, done = run.update(10.0, Env())  # 3 -> -3 rad the short way round: through pi
        self.assertAlmostEqual(target["yaw"], 3.0 + (2 * math.pi - 6.0) / 2, places=12)
        self.assertEqual((target["x"], target["speed"]), (10.0, 0.0))
        self.assertEqual(run.update(11.0, Env())[1], True)

    def test_parameters_and_no_start_trigger(self):
        board = Storyboard(load(fixture("parameters.xosc")))
        r = board.step(0.0, {"Ego": {"x": 25, "y": 0, "yaw": 0, "speed": 0},
                             "Bus": {"x": 0, "y": 0, "yaw": 0, "speed": 5},
                             "Walker": {"x": 0, "y": 9, "yaw": 0, "speed": 0}})
        bus = [c for c in r.started if c.actor == "Bus"][0]
        self.assertEqual(bus.target, {"speed": 5.0, "target_speed": 25.0, "acceleration": 8.0})

    def test_environment(self):
        board = Storyboard(load(fixture("environment.xosc")))
        ego = {"Ego": {"x": 0, "y": 0, "yaw": 0, "speed": 0}}
        first = board.step(0.0, ego)
        keys = dict(first.started[0].target["weather"])
        self.assertAlmostEqual(keys.pop("SunAltitude"), 30.0, places=12)
        self.assertEqual(keys, {"Precipitation": 0.6, "PrecipitationType": "rain",
                                "Visibility": 200.0, "SunAzimuth": 180.0, "Surface": "wet"})
        fired = None
        for k in range(1, 60):
            r = board.step(k * 0.1, ego)
            if r.started:
                fired = r
                break
        self.assertAlmostEqual(fired.time, 5.0)
        self.assertEqual(fired.started[0].target, {"environment": "SnowNight", "weather": {
            "Precipitation": 0.4, "PrecipitationType": "snow", "Visibility": 5000.0,
            "TimeOfDay": 21.5, "WindDirection": 90.0, "WindSpeed": 6.0, "Surface": "snow"}})
        self.assertTrue(fired.done)


class Weather(unittest.TestCase):
    def test_mapping(self):
        sc = load(fixture("environment.xosc"))
        self.assertEqual(weather_config(sc)["Surface"], "wet")
        env = m.Environment("e", (False, "2026-01-01T06:45:36"), m.Weather(
            precipitation=m.Precipitation("rain", None, 25.0)), 1.0)
        self.assertEqual(environment_to_weather(env), {
            "Precipitation": 1.0, "PrecipitationType": "rain", "TimeOfDay": 6.76, "Surface": "dry"})
        self.assertEqual(schedule_entry(m.Environment("e", weather=m.Weather(
            precipitation=m.Precipitation("dry", 0.0))), 30, 5),
            {"Time": 30.0, "Transition": 5.0, "Precipitation": 0.0})
        self.assertEqual(environment_to_weather(m.Environment("e", weather=m.Weather(
            sun=m.Sun(-math.pi / 2, -2.0)))), {"SunAltitude": -90.0, "SunAzimuth": 270.0})

    def test_surfaces(self):
        # boundaries between the surfaces' mu (0.8, 0.5, 0.25, 0.1), as factors of 0.8
        for factor, surface in ((1.2, "dry"), (0.82, "dry"), (0.80, "wet"), (0.6, "wet"),
                                (0.47, "wet"), (0.465, "snow"), (0.3, "snow"), (0.22, "snow"),
                                (0.215, "ice"), (0.0, "ice")):
            self.assertEqual(wx.surface_for_friction(factor), surface, factor)


class Conditions(unittest.TestCase):
    SPEEDS = [0, 5, 5, 0, 0, 5, 0]          # raw (speed > 1): F T T F F T F

    def fires(self, edge, speeds=None, delay=0):
        sc = scenario([event("E", trigger(speed_cond(edge, delay)), count=50)])
        results = run_worlds(sc, [still(v) for v in (speeds or self.SPEEDS)])
        return start_times(results, "E")

    def test_edges(self):
        self.assertEqual(self.fires("none"), [0.1, 0.2, 0.5])
        self.assertEqual(self.fires("rising"), [0.1, 0.5])
        self.assertEqual(self.fires("falling"), [0.3, 0.6])
        self.assertEqual(self.fires("risingOrFalling"), [0.1, 0.3, 0.5, 0.6])

    def test_no_edge_at_the_first_evaluation(self):
        self.assertEqual(self.fires("rising", [5, 5, 0, 5]), [0.3])
        self.assertEqual(self.fires("falling", [0, 5]), [])
        self.assertEqual(self.fires("none", [5, 0]), [0.0])

    def test_delays(self):
        self.assertEqual(self.fires("rising", delay=0.25, speeds=self.SPEEDS + [0] * 5),
                         [0.4, 0.8])
        # each edge fires once, even when the next edge comes before the first has fired
        self.assertEqual(self.fires("rising", delay=0.5, speeds=[0, 5, 0, 5, 0, 0, 0, 0, 0, 0]),
                         [0.6, 0.8])
        self.assertEqual(self.fires("none", delay=0.3, speeds=[0, 5, 5, 0, 0, 0, 0]),
                         [0.4, 0.5])

    def test_groups_or_of_and(self):
        both = (speed_cond(name="a"), speed_cond(entity="B", name="b"))
        sc = scenario([event("E", trigger(both, time_cond(0.5)), count=50)])
        worlds = [still(5), still(5, speed=5.0), still(0, speed=5.0), still(0), still(0),
                  still(0), still(0)]
        self.assertEqual(start_times(run_worlds(sc, worlds), "E"), [0.1, 0.5, 0.6])

    def test_triggering_entities_all(self):
        cond = speed_cond().replace('<EntityRef entityRef="A"/>',
                                    '<EntityRef entityRef="A"/><EntityRef entityRef="B"/>')
        for rule, expected in (("any", [0.0, 0.1]), ("all", [0.1])):
            sc = scenario([event("E", trigger(cond.replace('"any"', '"%s"' % rule)), count=9)])
            worlds = [still(5), still(5, speed=2.0), still(0)]
            self.assertEqual(start_times(run_worlds(sc, worlds), "E"), expected, rule)

    def test_rules(self):
        for rule, expected in (("greaterThan", [0.2]), ("lessThan", [0.0]),
                               ("equalTo", [0.1]), ("notEqualTo", [0.0, 0.2]),
                               ("greaterOrEqual", [0.1, 0.2]), ("lessOrEqual", [0.0, 0.1])):
            sc = scenario([event("E", trigger(speed_cond(rule=rule, value=3)), count=9)])
            worlds = [still(2), still(3.0000001), still(4)]
            self.assertEqual(start_times(run_worlds(sc, worlds), "E"), expected, rule)

    def entity_condition(self, xml, worlds):
        cond = ('<Condition name="c" delay="0" conditionEdge="none"><ByEntityCondition>'
                '<TriggeringEntities triggeringEntitiesRule="any"><EntityRef entityRef="A"/>'
                '</TriggeringEntities><EntityCondition>%s</EntityCondition></ByEntityCondition>'
                '</Condition>' % xml)
        sc = scenario([event("E", trigger(cond), count=9)])
        return start_times(run_worlds(sc, worlds), "E")

    def test_entity_conditions_in_the_executor(self):
        # B 50 m ahead (boxes 4 m long): 50 between reference points, 46 between the boxes
        rel = ('<RelativeDistanceCondition entityRef="B" value="%g" freespace="%s" '
               'relativeDistanceType="%s" rule="lessThan"/>')
        w = [still(0), still(0, bx=0), still(0)]
        for args, expected in (((50.5, "false", "longitudinal"), [0.0, 0.1, 0.2]),
                               ((46.5, "true", "longitudinal"), [0.0, 0.1, 0.2]),
                               ((45.5, "true", "longitudinal"), []),
                               ((1, "false", "lateral"), [0.0, 0.1, 0.2]),
                               ((50.5, "false", "euclidianDistance"), [0.0, 0.1, 0.2]),
                               ((49.5, "false", "cartesianDistance"), [])):
            self.assertEqual(self.entity_condition(rel % args, w), expected, args)
        road = ('<RelativeDistanceCondition entityRef="B" value="10" freespace="false" '
                'coordinateSystem="road" relativeDistanceType="longitudinal" rule="lessThan"/>')
        worlds = [still(0) for _ in range(2)]
        for w in worlds:
            w["A"].update(s=100.0, road="7")
        worlds[0]["B"].update(s=105.0, road="7")
        worlds[1]["B"].update(s=120.0, road="7")
        self.assertEqual(self.entity_condition(road, worlds), [0.0])
        ttc = ('<TimeToCollisionCondition value="5" freespace="true" rule="lessThan" '
               'relativeDistanceType="longitudinal"><TimeToCollisionConditionTarget>'
               '<EntityRef entityRef="B"/></TimeToCollisionConditionTarget>'
               '</TimeToCollisionCondition>')
        # gap 46 m: closing at 10 m/s -> 4.6 s; at 9 m/s -> 5.1 s; B faster -> never
        self.assertEqual(self.entity_condition(ttc, [still(10), still(9), still(10, speed=11.0)]),
                         [0.0])
        thw = ('<TimeHeadwayCondition entityRef="B" value="2" freespace="false" '
               'rule="greaterThan"/>')
        self.assertEqual(self.entity_condition(thw, [still(20), still(30), still(0)]), [0.0, 0.2])
        dist = ('<DistanceCondition value="3" freespace="true" rule="lessOrEqual"><Position>'
                '<WorldPosition x="7" y="0"/></Position></DistanceCondition>')
        self.assertEqual(self.entity_condition(dist, [still(0), still(0, ax=2.0)]), [0.1])
        reach = ('<ReachPositionCondition tolerance="1"><Position><WorldPosition x="3" y="4"/>'
                 '</Position></ReachPositionCondition>')
        self.assertEqual(self.entity_condition(reach, [still(0), still(0, ax=3.0, ay=3.0)]), [0.1])

    def test_missing_state_is_named(self):
        sc = scenario([event("E", trigger(speed_cond(entity="B")))])
        with self.assertRaises(ScenarioRuntimeError) as e:
            Storyboard(sc).step(0.0, {"A": still()["A"]})
        self.assertEqual(str(e.exception), "t=0: c (generated.xosc:1): the world has no state "
                                           "for entity 'B'")
        road = ('<Condition name="r" delay="0" conditionEdge="none"><ByEntityCondition>'
                '<TriggeringEntities triggeringEntitiesRule="any"><EntityRef entityRef="A"/>'
                '</TriggeringEntities><EntityCondition><RelativeDistanceCondition entityRef="B" '
                'value="10" freespace="false" coordinateSystem="road" relativeDistanceType='
                '"lateral" rule="lessThan"/></EntityCondition></ByEntityCondition></Condition>')
        with self.assertRaises(ScenarioRuntimeError) as e:
            Storyboard(scenario([event("E", trigger(road))])).step(0.0, still())
        self.assertEqual(str(e.exception), "t=0: r (generated.xosc:1): entity 'A''s state has "
                                           "no 't'")

    def test_time_must_increase(self):
        board = Storyboard(scenario([event("E", trigger(time_cond(5)))]))
        board.step(0.0, still())
        with self.assertRaises(ValueError):
            board.step(0.0, still())


class Geometry(unittest.TestCase):
    def body(self, x, y, yaw=0.0, speed=0.0, length=4.0, width=2.0, offset=0.0):
        return geo.Body("b", x, y, yaw, speed, speed * math.cos(yaw), speed * math.sin(yaw),
                        length, width, offset)

    def test_distances(self):
        a = self.body(0, 0, offset=1.0)              # box from -1 to 3 along x
        b = self.body(10, 3, yaw=math.pi / 2)        # box 4 long along y: x 9..11, y 1..5
        self.assertEqual(geo.signed_axis_distance(a, b, 0, False), 10.0)
        self.assertEqual(geo.signed_axis_distance(a, b, 0, True), 6.0)
        self.assertEqual(geo.signed_axis_distance(a, b, 1, True), 0.0)   # y 1..5 vs -1..1
        self.assertAlmostEqual(geo.signed_axis_distance(b, a, 0, False), -3.0, places=12)
        self.assertAlmostEqual(geo.euclidean(a, b, False), math.hypot(10, 3))
        self.assertAlmostEqual(geo.euclidean(a, b, True), 6.0)  # corner (3, 1) to edge x = 9
        self.assertEqual(geo.polygon_distance(a.corners(), self.body(1, 0).corners()), 0.0)
        self.assertAlmostEqual(geo.point_euclidean(a, 6, 5, True), 5.0)

    def test_ttc_and_headway(self):
        a, b = self.body(0, 0, speed=20), self.body(30, 0, speed=10)
        self.assertAlmostEqual(geo.time_to_collision(a, b, "longitudinal", True), 2.6)
        self.assertAlmostEqual(geo.time_to_collision(a, b, "euclidianDistance", False), 3.0)
        self.assertEqual(geo.time_to_collision(b, a, "longitudinal", False), 3.0)
        self.assertEqual(geo.time_to_collision(a, self.body(30, 0, speed=25), "longitudinal",
                                               False), math.inf)
        self.assertEqual(geo.time_headway(a, b, False, "entity", None), 1.5)
        self.assertEqual(geo.time_headway(b, a, True, "entity", None), -2.6)
        self.assertEqual(geo.time_headway(self.body(0, 0), b, False, "entity", None), math.inf)


class Execution(unittest.TestCase):
    def test_event_execution_count(self):
        sc = scenario([event("E", trigger(time_cond(0)), count=2)])
        results = run_worlds(sc, [still()] * 4)
        self.assertEqual(transitions(results, "E"), [
            (0.0, "E", "startTransition", "standbyState", "runningState"),
            (0.0, "E", "endTransition", "runningState", "standbyState"),
            (0.1, "E", "startTransition", "standbyState", "runningState"),
            (0.1, "E", "endTransition", "runningState", "completeState")])
        self.assertTrue(results[1].done)

    def test_group_execution_count_restarts_its_children(self):
        sc = scenario([event("E", trigger(time_cond(0)))], group_count=3)
        results = run_worlds(sc, [still()] * 5)
        self.assertEqual(start_times(results, "G"), [0.0, 0.1, 0.2])
        self.assertEqual(start_times(results, "E"), [0.0, 0.1, 0.2])
        self.assertEqual([tr[4] for tr in transitions(results, "G", "endTransition")],
                         ["standbyState", "standbyState", "completeState"])

    def test_state_condition_chain(self):
        long_speed = speed_action(100)
        sc = scenario([
            event("E1", trigger(time_cond(0.2)), action=long_speed),
            event("E2", trigger(state_cond("event", "E1", "startTransition")), "parallel"),
            event("E3", trigger(state_cond("action", "E2_action", "endTransition")), "parallel"),
            event("E4", trigger(state_cond("event", "E1", "runningState", "rising")), "parallel"),
            event("E5", trigger(state_cond("maneuverGroup", "S::Act::G", "runningState")),
                  "parallel"),
            event("E6", trigger(state_cond("event", "E3", "completeState")), "parallel"),
        ], act_stop=trigger(time_cond(0.8), tag="StopTrigger"))
        results = run_worlds(sc, [still()] * 10)
        # esmini's order: a condition sees the transitions made earlier in the same step's
        # walk; an action's end (at the end of a step) is seen at the next step
        self.assertEqual(start_times(results, "E1"), [0.2])
        self.assertEqual(start_times(results, "E2"), [0.2])   # E1 started earlier in the walk
        self.assertEqual(start_times(results, "E3"), [0.3])   # E2's action ended at 0.2
        self.assertEqual(start_times(results, "E4"), [0.2])
        self.assertEqual(start_times(results, "E5"), [0.0])   # the group runs from 0.0
        self.assertEqual(start_times(results, "E6"), [0.4])
        stops = transitions(results, kind="stopTransition")
        self.assertEqual(stops, [
            (0.8, "Act", "stopTransition", "runningState", "completeState"),
            (0.8, "G", "stopTransition", "runningState", "completeState"),
            (0.8, "M", "stopTransition", "runningState", "completeState"),
            (0.8, "E1", "stopTransition", "runningState", "completeState"),
            (0.8, "E1_action", "stopTransition", "runningState", "completeState")])
        self.assertEqual(results[8].ended, [("S::Act::G::M::E1::E1_action", "A", "stop")])
        self.assertTrue(results[8].done)

    def test_end_and_skip_transitions_as_conditions(self):
        sc = scenario([
            event("Long", trigger(time_cond(0)), action=speed_action(100)),
            event("Over", trigger(time_cond(0.3)), "overwrite"),
            event("Skip", trigger(time_cond(0.1)), "skip"),
            event("AfterStop", trigger(state_cond("event", "Long", "endTransition")), "parallel"),
            event("AfterSkip", trigger(state_cond("event", "Skip", "skipTransition", "rising")),
                  "parallel"),
        ])
        results = run_worlds(sc, [still()] * 6)
        self.assertEqual(transitions(results, "Skip")[:2], [
            (0.1, "Skip", "skipTransition", "standbyState", "standbyState"),
            (0.2, "Skip", "skipTransition", "standbyState", "standbyState")])
        # overwritten: Long ends (esmini's reading), its action's run is stopped
        self.assertEqual(transitions(results, "Long", "endTransition"),
                         [(0.3, "Long", "endTransition", "runningState", "completeState")])
        self.assertEqual(start_times(results, "AfterStop"), [0.3])   # later in the same walk
        self.assertEqual(start_times(results, "AfterSkip"), [0.1])
        # Over ended at 0.3 with Long stopped: Skip starts at 0.4, nothing running
        self.assertEqual(start_times(results, "Skip"), [0.4])

    def test_parallel_and_domain_override(self):
        sc = scenario([
            event("Slow", trigger(time_cond(0)), action=speed_action(100)),
            event("Lane", trigger(time_cond(0.1)), "parallel", action=(
                '<PrivateAction><LateralAction><LaneChangeAction><LaneChangeActionDynamics '
                'dynamicsShape="linear" dynamicsDimension="time" value="10"/><LaneChangeTarget>'
                '<AbsoluteTargetLane value="-2"/></LaneChangeTarget></LaneChangeAction>'
                '</LateralAction></PrivateAction>')),
            event("Fast", trigger(time_cond(0.2)), "parallel", action=speed_action(50, 5)),
        ])
        results = run_worlds(sc, [still()] * 4)
        self.assertEqual(transitions(results, "Slow_action", "stopTransition"),
                         [(0.2, "Slow_action", "stopTransition", "runningState", "completeState")])
        self.assertEqual(transitions(results, "Slow", "endTransition"),
                         [(0.2, "Slow", "endTransition", "runningState", "completeState")])
        self.assertEqual([(c.action.split("::")[-1],
                           round(c.target["speed"], 9) if "speed" in c.target else c.target["lane"])
                          for c in results[3].running],
                         [("Lane_action", "-2"), ("Fast_action", 0.5)])

    def test_storyboard_stop_trigger_with_delay(self):
        sc = scenario([event("E", trigger(time_cond(10)))],
                      board_stop=trigger(speed_cond("rising", 0.3), tag="StopTrigger"))
        results = run_worlds(sc, [still(0), still(5)] + [still(5)] * 5)
        self.assertEqual(transitions(results, "Storyboard", "stopTransition"),
                         [(0.4, "Storyboard", "stopTransition", "runningState", "completeState")])
        self.assertEqual(transitions(results, "E", "stopTransition"),
                         [(0.4, "E", "stopTransition", "standbyState", "completeState")])
        self.assertTrue(results[4].done)
        self.assertEqual(len(results), 7)
        self.assertEqual(results[5].transitions, [])

    def test_act_start_trigger_and_stop_before_start(self):
        sc = scenario([event("E", trigger(time_cond(0)))], act_start=trigger(time_cond(0.5)),
                      act_stop=trigger(time_cond(0.2), tag="StopTrigger"))
        results = run_worlds(sc, [still()] * 8)
        self.assertEqual(transitions(results, "Act"), [
            (0.2, "Act", "stopTransition", "standbyState", "completeState")])
        self.assertEqual(start_times(results, "E"), [])


class Actions(unittest.TestCase):
    class Env:
        def __init__(self, **bodies):
            self.bodies = bodies

        def body(self, name, user):
            return self.bodies[name]

        def need(self, body, key, user):
            value = getattr(body, key)
            if value is None:
                raise ScenarioRuntimeError("no %s" % key)
            return value

        def error(self, user, message):
            return ScenarioRuntimeError(message)

    def car(self, speed=10.0, x=0.0, lane="-1"):
        return geo.Body("car", x, 0.0, 0.0, speed, speed, 0.0, 4.0, 2.0, lane=lane)

    def speed(self, shape, dim, value, target, t, speed=10.0, **env):
        spec = m.SpeedAction(m.Dynamics(shape, dim, value), target)
        e = self.Env(car=self.car(speed), **env)
        return act.make_run("a", spec, "car", 0.0, e).update(t, e)

    def test_speed_shapes(self):
        target = m.AbsoluteTargetSpeed(20.0)
        self.assertEqual(self.speed("step", "time", 0, target, 0.0)[0]["speed"], 20.0)
        self.assertEqual(self.speed("linear", "time", 4, target, 1.0)[0],
                         {"speed": 12.5, "target_speed": 20.0, "acceleration": 2.5})
        self.assertEqual(self.speed("linear", "rate", -2, target, 1.0)[0]["speed"], 12.0)
        self.assertEqual(self.speed("cubic", "time", 4, target, 2.0)[0]["speed"], 15.0)
        self.assertAlmostEqual(self.speed("cubic", "time", 4, target, 1.0)[0]["speed"], 11.5625)
        self.assertAlmostEqual(self.speed("sinusoidal", "time", 4, target, 1.0)[0]["speed"],
                               10 + 10 * (1 - math.cos(math.pi / 4)) / 2)
        # 10 -> 20 m/s over 75 m: 2 x 75 / 30 = 5 s
        self.assertEqual(self.speed("linear", "distance", 75, target, 2.5)[0]["speed"], 15.0)

    def test_speed_goal_and_relative_targets(self):
        target = m.AbsoluteTargetSpeed(10.05)
        self.assertEqual(self.speed("linear", "time", 1, target, 0.5)[1], False)  # not yet
        self.assertEqual(self.speed("linear", "time", 1, target, 1.0)[1], True)   # within 0.1
        self.assertEqual(self.speed("step", "time", 0, m.AbsoluteTargetSpeed(10.2), 1.0)[1], False)
        lead = self.car(15.0)
        factor = m.RelativeTargetSpeed("lead", 1.2, "factor", False)
        self.assertAlmostEqual(self.speed("step", "time", 0, factor, 0, lead=lead)[0]["speed"], 18.0)
        cont = m.RelativeTargetSpeed("lead", 0.0, "delta", True)
        target, done = self.speed("step", "time", 0, cont, 5.0, speed=15.0, lead=lead)
        self.assertEqual((target["speed"], done), (15.0, False))  # continuous: never ends

    def test_lane_change(self):
        self.assertEqual([act.shift_lane(lane, v) for lane, v in
                          (("-2", 1), ("-1", 1), ("1", 1), ("2", 1), ("-1", -1), ("-1", 0),
                           ("-2", 3))], ["-1", "1", "-1", "1", "-2", "-1", "2"])
        spec = m.LaneChangeAction(m.Dynamics("linear", "distance", 40.0),
                                  m.RelativeTargetLane("ego", 1), 0.25)
        ego = self.car(lane="-2")
        e = self.Env(car=self.car(lane="-1"), ego=ego)
        run = act.make_run("a", spec, "car", 0.0, e)
        e.bodies["car"] = self.car(x=30.0)
        target, done = run.update(1.0, e)
        self.assertEqual(target, {"lane": "-1", "from_lane": "-1", "road": None, "offset": 0.25,
                                  "progress": 0.75})
        e.bodies["car"] = self.car(x=40.0)
        self.assertEqual(run.update(2.0, e)[1], True)
        e = self.Env(car=self.car(), ego=self.car(lane=None))
        with self.assertRaises(ScenarioRuntimeError):
            act.make_run("a", spec, "car", 0.0, e)


if __name__ == "__main__":
    unittest.main()
