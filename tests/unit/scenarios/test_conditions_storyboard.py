"""The storyboard on issue 25's conditions and instant actions (convoy_scenario.conditions):
TraveledDistance, EndOfRoad / Offroad / StandStill with durations, Collision, Acceleration,
RelativeSpeed, RelativeClearance, Parameter / Variable conditions with Parameter /
Variable actions, traffic signals (actions and controller phases), positions other than
world ones in conditions, selectTriggeringEntities, empty triggers, actions without a run
yet, and a missing world key."""

import unittest

from test_xosc_support import act, load_text, world

from convoy_scenario import ScenarioRuntimeError, Storyboard

STOP = ('<PrivateAction><LongitudinalAction><SpeedAction><SpeedActionDynamics '
        'dynamicsShape="step" dynamicsDimension="time" value="0"/><SpeedActionTarget>'
        '<AbsoluteTargetSpeed value="0"/></SpeedActionTarget></SpeedAction>'
        '</LongitudinalAction></PrivateAction>')


def by_entity(cond_xml, who="Ego", edge="none", rule="any", name="c"):
    return ('<StartTrigger><ConditionGroup><Condition name="%s" delay="0" conditionEdge="%s">'
            '<ByEntityCondition><TriggeringEntities triggeringEntitiesRule="%s">%s'
            '</TriggeringEntities><EntityCondition>%s</EntityCondition></ByEntityCondition>'
            '</Condition></ConditionGroup></StartTrigger>'
            % (name, edge, rule, "".join('<EntityRef entityRef="%s"/>' % w
                                         for w in who.split(",")), cond_xml))


def by_value(cond_xml, edge="none"):
    return ('<StartTrigger><ConditionGroup><Condition name="v" delay="0" conditionEdge="%s">'
            '<ByValueCondition>%s</ByValueCondition></Condition></ConditionGroup></StartTrigger>'
            % (edge, cond_xml))


def first_start(board, worlds, dt=0.5):
    """The time of the first step at which the event S::A::G::M::E starts, or None."""
    for i, w in enumerate(worlds):
        r = board.step(i * dt, w)
        for tr in r.transitions:
            if tr.element == "S::A::G::M::E" and tr.transition == "startTransition":
                return i * dt
    return None


def event_on(cond, **kw):
    return Storyboard(load_text(story=act([("a", STOP)], event_start=cond), **kw))


class EntityConditions(unittest.TestCase):
    def test_traveled_distance(self):
        b = event_on(by_entity('<TraveledDistanceCondition value="10"/>'))
        worlds = [world(Ego={"odometer": d}) for d in (0, 5, 9.9, 10, 12)]
        self.assertEqual(first_start(b, worlds), 1.5)

    def test_durations(self):
        for xml, key, on in (('<EndOfRoadCondition duration="1"/>', "end_of_road", True),
                             ('<OffroadCondition duration="1"/>', "offroad", True),
                             ('<StandStillCondition duration="1"/>', "speed", 0.0)):
            with self.subTest(xml=xml):
                off = False if key != "speed" else 5.0
                values = [off, on, on, off, on, on, on]   # held 1 s from t = 2 on: 3.0
                b = event_on(by_entity(xml))
                self.assertEqual(first_start(b, [world(Ego={key: v}) for v in values]), 3.0)

    def test_collision(self):
        b = event_on(by_entity('<CollisionCondition><EntityRef entityRef="Target"/>'
                               '</CollisionCondition>'))
        self.assertEqual(first_start(b, [world(), world(Ego={"collisions": ["Target"]})]), 0.5)
        b = event_on(by_entity('<CollisionCondition><ByType objectType="pedestrian"/>'
                               '</CollisionCondition>'))
        self.assertIsNone(first_start(b, [world(Ego={"collisions": ["Target"]})] * 2))

    def test_acceleration(self):
        b = event_on(by_entity('<AccelerationCondition value="-3" rule="lessThan" '
                               'direction="longitudinal"/>'))
        self.assertEqual(first_start(b, [world(Ego={"ax": -1}),
                                         world(Ego={"ax": 0, "ay": -4, "yaw": 1.5707963})]), 0.5)
        b = event_on(by_entity('<AccelerationCondition value="4.9" rule="greaterThan"/>'))
        self.assertEqual(first_start(b, [world(Ego={"ax": 3, "ay": 4})]), 0.0)
        # no direction: the magnitude, negative when braking (esmini)
        b = event_on(by_entity('<AccelerationCondition value="-4.9" rule="lessThan"/>'))
        self.assertEqual(first_start(b, [world(Ego={"ax": 3, "ay": 4}),
                                         world(Ego={"ax": -3, "ay": 4})]), 0.5)

    def test_relative_speed(self):
        b = event_on(by_entity('<RelativeSpeedCondition entityRef="Target" value="2" '
                               'rule="greaterThan"/>'))
        self.assertEqual(first_start(b, [world(Ego={"speed": 10}, Target={"speed": 9}),
                                         world(Ego={"speed": 10}, Target={"speed": 7})]), 0.5)

    def test_relative_clearance(self):
        b = event_on(by_entity('<RelativeClearanceCondition distanceForward="30" '
                               'distanceBackward="10" freeSpace="false" oppositeLanes="false">'
                               '<RelativeLaneRange from="1" to="1"/></RelativeClearanceCondition>'))
        # Ego in lane -2, Target in lane -1 (one lane to its left): 20 m ahead blocks the
        # range, 40 m ahead is beyond distanceForward
        worlds = [world(Ego={"lane": -2}, Target={"lane": -1}),
                  world(Ego={"lane": -2}, Target={"lane": -1, "s": 40.0})]
        self.assertEqual(first_start(b, worlds), 0.5)


class ValueConditions(unittest.TestCase):
    PARAMS = '<ParameterDeclaration name="n" parameterType="integer" value="10"/>'

    def test_parameter_action_and_condition(self):
        set_n = ('<GlobalAction><ParameterAction parameterRef="n"><ModifyAction><Rule>'
                 '<AddValue value="1"/></Rule></ModifyAction></ParameterAction></GlobalAction>')
        story = act([("inc", set_n)], actors=(), name="A0", maneuver="M0",
                    event_start=by_value('<SimulationTimeCondition value="1" '
                                         'rule="greaterOrEqual"/>')) + \
            act([("a", STOP)], event_start=by_value('<ParameterCondition parameterRef="n" '
                                                   'value="10" rule="greaterThan"/>'))
        b = Storyboard(load_text(story=story, params=self.PARAMS))
        # set at 1.0 by an event earlier in the walk: seen in the same step (esmini's order)
        self.assertEqual(first_start(b, [world()] * 6), 1.0)
        self.assertEqual(b.parameters["n"], 11)

    def test_variable_condition(self):
        var = ('<VariableDeclarations><VariableDeclaration name="flag" variableType="boolean" '
               'value="false"/></VariableDeclarations>')
        set_v = ('<GlobalAction><VariableAction variableRef="flag"><SetAction value="true"/>'
                 '</VariableAction></GlobalAction>')
        story = act([("set", set_v)], actors=(), name="A0", maneuver="M0") + \
            act([("a", STOP)], event_start=by_value('<VariableCondition variableRef="flag" '
                                                   'value="true" rule="equalTo"/>'))
        b = Storyboard(load_text(story=story, variables=var))
        self.assertEqual(first_start(b, [world()] * 3), 0.0)   # set earlier in the same walk

    def test_traffic_signals(self):
        net = ('<TrafficSignals><TrafficSignalController name="c1" delay="1"><Phase name="go" '
               'duration="2"><TrafficSignalState trafficSignalId="5" state="green"/></Phase>'
               '<Phase name="stop" duration="2"><TrafficSignalState trafficSignalId="5" '
               'state="red"/></Phase></TrafficSignalController></TrafficSignals>')
        b = event_on(by_value('<TrafficSignalCondition name="5" state="red"/>'), network=net)
        self.assertEqual(first_start(b, [world()] * 10), 3.0)
        b = event_on(by_value('<TrafficSignalControllerCondition trafficSignalControllerRef="c1" '
                              'phase="go"/>'), network=net)
        self.assertEqual(first_start(b, [world()] * 10), 1.0)
        init = ('<GlobalAction><InfrastructureAction><TrafficSignalAction>'
                '<TrafficSignalStateAction name="7" state="off"/></TrafficSignalAction>'
                '</InfrastructureAction></GlobalAction>')
        b = event_on(by_value('<TrafficSignalCondition name="7" state="off"/>'), init=init)
        self.assertEqual(first_start(b, [world()] * 3), 0.0)   # Init's, before the walk


class Reading(unittest.TestCase):
    def test_condition_errors_and_along_route(self):
        from convoy_scenario import ScenarioError
        params = '<ParameterDeclaration name="w" parameterType="string" value="a"/>'
        for cond, message in (
                (by_value('<ParameterCondition parameterRef="x" value="1" rule="equalTo"/>'),
                 "<ParameterCondition> parameterRef: no global parameter x (declared: w)"),
                (by_value('<ParameterCondition parameterRef="w" value="1" rule="lessThan"/>'),
                 "<ParameterCondition> rule: lessThan compares numbers; w is a string"),
                (by_entity('<CollisionCondition><ByType objectType="tree"/></CollisionCondition>'),
                 "<ByType> objectType: 'tree' is not one of pedestrian, vehicle, miscellaneous, "
                 "external"),
                (by_entity('<RelativeClearanceCondition freeSpace="true" oppositeLanes="false">'
                           '<RelativeLaneRange from="2" to="1"/></RelativeClearanceCondition>'),
                 "<RelativeLaneRange> from: 2 is greater than to 1")):
            with self.subTest(message=message):
                with self.assertRaises(ScenarioError) as e:
                    load_text(story=act([("a", STOP)], event_start=cond), params=params)
                self.assertIn(message, str(e.exception))
        s = load_text(story=act([("a", STOP)], event_start=by_entity(
            '<RelativeDistanceCondition entityRef="Target" value="5" freespace="false" '
            'rule="lessThan" relativeDistanceType="longitudinal" alongRoute="true"/>')))
        test = s.stories[0].acts[0].groups[0].maneuvers[0].events[0].start_trigger.groups[0][0].test
        self.assertEqual((test.along_route, test.coordinate_system), (True, "road"))


class Storyboarding(unittest.TestCase):
    def test_select_triggering_entities(self):
        story = act([("a", STOP)], actors=(), select=True,
                    start=by_entity('<SpeedCondition value="5" rule="greaterThan"/>',
                                    who="Ego,Target"))
        b = Storyboard(load_text(story=story))
        b.step(0, world())
        r = b.step(0.5, world(Target={"speed": 8}))
        self.assertEqual([c.actor for c in r.started], ["Target"])

    def test_positions_in_conditions(self):
        reach = ('<ReachPositionCondition tolerance="1"><Position><RelativeObjectPosition '
                 'entityRef="Target" dx="-5" dy="0"/></Position></ReachPositionCondition>')
        b = event_on(by_entity(reach))
        self.assertEqual(first_start(b, [world(), world(Ego={"x": 15.5})]), 0.5)
        lane = ('<ReachPositionCondition tolerance="1"><Position><LanePosition roadId="1" '
                'laneId="-1" s="30"/></Position></ReachPositionCondition>')
        b = event_on(by_entity(lane))
        with self.assertRaises(ScenarioRuntimeError) as e:
            b.step(0, world())
        self.assertIn("a LanePosition needs the road map", str(e.exception))
        b = Storyboard(b.scenario, resolve_position=lambda p, w: (p["s"], -1.75))
        self.assertEqual(first_start(b, [world(), world(Ego={"x": 29.5})]), 0.5)

    def test_actions_without_a_run_end_at_once(self):
        init = ('<Private entityRef="Ego"><PrivateAction><ActivateControllerAction '
                'longitudinal="true"/></PrivateAction></Private>')
        r = Storyboard(load_text(init=init)).step(0, world())
        self.assertEqual([(c.kind, c.target) for c in r.running],
                         [("ActivateControllerAction", {})])
        self.assertEqual(r.ended, [("Init[0]", "Ego", "end")])

    def test_empty_triggers_are_none(self):
        story = act([("a", STOP)], start="<StartTrigger/><StopTrigger/>",
                    event_start="<StartTrigger/>")
        b = Storyboard(load_text(story=story))
        self.assertEqual(first_start(b, [world()]), 0.0)

    def test_missing_world_key(self):
        b = event_on(by_entity('<TraveledDistanceCondition value="10"/>'))
        w = world()
        del w["Ego"]["odometer"]
        with self.assertRaises(ScenarioRuntimeError) as e:
            b.step(0, w)
        self.assertEqual(str(e.exception), "t=0: c (generated.xosc:20): entity 'Ego''s state "
                                           "has no 'odometer'")


if __name__ == "__main__":
    unittest.main()
