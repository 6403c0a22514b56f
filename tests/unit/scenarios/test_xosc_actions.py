"""The reader on issue 25's actions: controller actions, LongitudinalDistance, SpeedProfile,
LaneOffset, LateralDistance, Synchronize, AcquirePosition, Visibility, LightState,
trailer actions, Parameter/Variable, Infrastructure and Traffic actions, and the Route,
Maneuver and Environment catalogs."""

import os
import shutil
import tempfile
import unittest

from test_xosc_support import PATH, act, load_text, private, text

from convoy_scenario import ScenarioError, loads
from convoy_scenario import model as m


def spec(action_xml, **kw):
    return load_text(init=private(action_xml), **kw).init[0].spec


def lon(x):
    return "<LongitudinalAction>%s</LongitudinalAction>" % x


def lat(x):
    return "<LateralAction>%s</LateralAction>" % x


class PrivateActions(unittest.TestCase):
    def test_controller_actions(self):
        self.assertEqual(spec('<ActivateControllerAction longitudinal="true" lateral="false"/>'),
                         m.ActivateControllerAction(False, True))
        self.assertEqual(spec('<ControllerAction><ActivateControllerAction lateral="true"/>'
                              '</ControllerAction>'), m.ActivateControllerAction(True))
        a = spec('<ControllerAction><AssignControllerAction activateLongitudinal="true">'
                 '<Controller name="c"><Properties><Property name="p" value="1"/></Properties>'
                 '</Controller></AssignControllerAction></ControllerAction>')
        self.assertEqual(a, m.AssignControllerAction(m.Controller("c", None, (("p", "1"),)),
                                                     None, None, True))
        o = spec('<ControllerAction><OverrideControllerValueAction>'
                 '<Throttle active="true" value="0.5" maxRate="1"/>'
                 '<Brake active="false"><BrakePercent value="0.2"/></Brake>'
                 '<Gear active="true"><AutomaticGear gear="d"/></Gear>'
                 '</OverrideControllerValueAction></ControllerAction>')
        self.assertEqual(o.overrides[0], m.ControllerOverride("Throttle", True, (
            ("value", 0.5), ("maxRate", 1.0))))
        self.assertEqual(o.overrides[1].values, (("BrakePercent.value", 0.2),))
        self.assertEqual(o.overrides[2].values, (("gear", "d"),))

    def test_longitudinal(self):
        d = spec(lon('<LongitudinalDistanceAction entityRef="Target" timeGap="1.5" '
                     'freespace="true" continuous="false" coordinateSystem="road" '
                     'displacement="leadingReferencedEntity"><DynamicConstraints '
                     'maxAcceleration="3" maxDeceleration="6" maxSpeed="40"/>'
                     '</LongitudinalDistanceAction>'))
        self.assertEqual(d, m.LongitudinalDistanceAction(
            "Target", None, 1.5, True, False, "road", "leadingReferencedEntity",
            m.DynamicConstraints(3.0, 6.0, 40.0)))
        with self.assertRaises(ScenarioError) as e:
            spec(lon('<LongitudinalDistanceAction entityRef="Target" distance="5" timeGap="1" '
                     'freespace="true" continuous="true"/>'))
        self.assertIn("needs exactly one of the attributes distance and timeGap", str(e.exception))
        p = spec(lon('<SpeedProfileAction followingMode="follow"><SpeedProfileEntry time="0" '
                     'speed="0"/><SpeedProfileEntry speed="10"/></SpeedProfileAction>'))
        self.assertEqual(p.entries, (m.SpeedProfileEntry(0.0, 0.0), m.SpeedProfileEntry(10.0)))
        # esmini: a transition over no time is a step; rate with any shape
        s = spec(lon('<SpeedAction><SpeedActionDynamics dynamicsShape="linear" '
                     'dynamicsDimension="time" value="0"/><SpeedActionTarget>'
                     '<AbsoluteTargetSpeed value="3"/></SpeedActionTarget></SpeedAction>'))
        self.assertEqual(s.dynamics.shape, "step")
        s = spec(lon('<SpeedAction><SpeedActionDynamics dynamicsShape="sinusoidal" '
                     'dynamicsDimension="rate" value="2"/><SpeedActionTarget>'
                     '<AbsoluteTargetSpeed value="3"/></SpeedActionTarget></SpeedAction>'))
        self.assertEqual(s.dynamics, m.Dynamics("sinusoidal", "rate", 2.0))

    def test_lateral(self):
        o = spec(lat('<LaneOffsetAction continuous="false"><LaneOffsetActionDynamics '
                     'dynamicsShape="sinusoidal" maxLateralAcc="0.5"/><LaneOffsetTarget>'
                     '<AbsoluteTargetLaneOffset value="-1.2"/></LaneOffsetTarget>'
                     '</LaneOffsetAction>'))
        self.assertEqual(o, m.LaneOffsetAction("sinusoidal", 0.5, -1.2, None, False))
        r = spec(lat('<LaneOffsetAction continuous="true"><LaneOffsetActionDynamics '
                     'dynamicsShape="step"/><LaneOffsetTarget><RelativeTargetLaneOffset '
                     'entityRef="Target" value="1"/></LaneOffsetTarget></LaneOffsetAction>'))
        self.assertEqual((r.entity, r.continuous), ("Target", True))
        d = spec(lat('<LateralDistanceAction entityRef="Target" distance="3" freespace="false" '
                     'continuous="true" coordinateSystem="road"/>'))
        self.assertEqual(d, m.LateralDistanceAction("Target", 3.0, False, True, "road"))

    def test_synchronize(self):
        s = spec('<SynchronizeAction masterEntityRef="Target"><TargetPositionMaster>'
                 '<LanePosition roadId="1" laneId="-1" s="100"/></TargetPositionMaster>'
                 '<TargetPosition><LanePosition roadId="1" laneId="1" s="50"/></TargetPosition>'
                 '<FinalSpeed><RelativeSpeedToMaster value="2" speedTargetValueType="delta">'
                 '<TargetTimeSteadyState time="3"/></RelativeSpeedToMaster></FinalSpeed>'
                 '</SynchronizeAction>')
        self.assertEqual(s.master, "Target")
        self.assertEqual(s.position, m.LanePosition("1", "1", 50.0))
        self.assertEqual(s.final_speed, m.FinalSpeed("relative", 2.0, "delta", ("time", 3.0)))
        a = spec('<SynchronizeAction masterEntityRef="Target"><TargetPositionMaster>'
                 '<WorldPosition x="1" y="2"/></TargetPositionMaster><TargetPosition>'
                 '<WorldPosition x="3" y="4"/></TargetPosition><FinalSpeed><AbsoluteSpeed '
                 'value="5"><TargetDistanceSteadyState distance="10"/></AbsoluteSpeed>'
                 '</FinalSpeed></SynchronizeAction>')
        self.assertEqual(a.final_speed, m.FinalSpeed("absolute", 5.0, None, ("distance", 10.0)))

    def test_routing_visibility_appearance_trailers(self):
        self.assertEqual(spec('<RoutingAction><AcquirePositionAction><Position><WorldPosition '
                              'x="1" y="2"/></Position></AcquirePositionAction></RoutingAction>'),
                         m.AcquirePositionAction(m.WorldPosition(1.0, 2.0)))
        self.assertEqual(spec('<VisibilityAction graphics="false" traffic="true" sensors="true"/>'),
                         m.VisibilityAction(False, True, True))
        light = spec('<AppearanceAction><LightStateAction transitionTime="0.5"><LightType>'
                     '<VehicleLight vehicleLightType="fogLights"/></LightType><LightState '
                     'mode="on" luminousIntensity="100"><Color colorType="red"><ColorRgb red="1" '
                     'green="0" blue="0"/></Color></LightState></LightStateAction>'
                     '</AppearanceAction>')
        self.assertEqual((light.light_type, light.mode, light.transition_time, light.color),
                         ("fogLights", "on", 0.5, ("red", (("red", 1.0), ("green", 0.0),
                                                           ("blue", 0.0)))))
        self.assertEqual(spec('<TrailerAction><ConnectTrailerAction trailerRef="Target"/>'
                              '</TrailerAction>'), m.ConnectTrailerAction("Target"))
        self.assertEqual(spec('<TrailerAction><DisconnectTrailerAction/></TrailerAction>'),
                         m.DisconnectTrailerAction())


class GlobalActions(unittest.TestCase):
    PARAMS = ('<ParameterDeclaration name="n" parameterType="double" value="1"/>'
              '<ParameterDeclaration name="w" parameterType="string" value="a"/>')

    def glob(self, xml, **kw):
        kw.setdefault("params", self.PARAMS)
        return load_text(init='<GlobalAction>%s</GlobalAction>' % xml, **kw).init[0].spec

    def test_parameter_and_variable_actions(self):
        self.assertEqual(self.glob('<ParameterAction parameterRef="n"><SetAction value="11"/>'
                                   '</ParameterAction>'), m.ParameterAction("n", "set", 11.0))
        self.assertEqual(self.glob('<ParameterAction parameterRef="n"><ModifyAction><Rule>'
                                   '<MultiplyByValue value="2"/></Rule></ModifyAction>'
                                   '</ParameterAction>'), m.ParameterAction("n", "multiply", 2.0))
        var = self.glob('<VariableAction variableRef="v"><ModifyAction><Rule><AddValue value="1"/>'
                        '</Rule></ModifyAction></VariableAction>',
                        variables='<VariableDeclarations><VariableDeclaration name="v" '
                                  'variableType="integer" value="0"/></VariableDeclarations>')
        self.assertEqual(var, m.ParameterAction("v", "add", 1.0, True))
        for xml, message in (
                ('<ParameterAction parameterRef="x"><SetAction value="1"/></ParameterAction>',
                 "<ParameterAction> parameterRef: no global parameter x (declared: n, w)"),
                ('<ParameterAction parameterRef="w"><ModifyAction><Rule><AddValue value="1"/>'
                 '</Rule></ModifyAction></ParameterAction>', "<AddValue> is for numbers; w is a "
                 "string"),
                ('<ParameterAction parameterRef="n"><SetAction value="x"/></ParameterAction>',
                 "<SetAction> value: expected a number, got 'x'")):
            with self.subTest(xml=xml):
                with self.assertRaises(ScenarioError) as e:
                    self.glob(xml)
                self.assertIn(message, str(e.exception))

    def test_infrastructure_and_traffic(self):
        net = ('<TrafficSignals><TrafficSignalController name="c1" delay="1"><Phase name="go" '
               'duration="10"><TrafficSignalState trafficSignalId="5" state="off;off;on"/>'
               '</Phase><Phase name="stop" duration="5"/></TrafficSignalController>'
               '</TrafficSignals>')
        self.assertEqual(self.glob('<InfrastructureAction><TrafficSignalAction>'
                                   '<TrafficSignalStateAction name="5" state="on;off;off"/>'
                                   '</TrafficSignalAction></InfrastructureAction>'),
                         m.TrafficSignalStateAction("5", "on;off;off"))
        s = load_text(network=net, init='<GlobalAction><InfrastructureAction><TrafficSignalAction>'
                      '<TrafficSignalControllerAction trafficSignalControllerRef="c1" '
                      'phase="stop"/></TrafficSignalAction></InfrastructureAction></GlobalAction>')
        self.assertEqual(s.init[0].spec, m.TrafficSignalControllerAction("c1", "stop"))
        self.assertEqual(s.traffic_signal_controllers[0].phases[0].states,
                         (m.TrafficSignalState("5", "off;off;on"),))
        with self.assertRaises(ScenarioError) as e:
            load_text(network=net, init='<GlobalAction><InfrastructureAction><TrafficSignalAction>'
                      '<TrafficSignalControllerAction trafficSignalControllerRef="c1" '
                      'phase="red"/></TrafficSignalAction></InfrastructureAction></GlobalAction>')
        self.assertIn("phase: controller 'c1' has no phase 'red' (phases: go, stop)",
                      str(e.exception))
        swarm = self.glob('<TrafficAction><TrafficSwarmAction innerRadius="10" semiMajorAxis="100" '
                          'semiMinorAxis="50" numberOfVehicles="5" velocity="20" offset="0">'
                          '<CentralObject entityRef="Ego"/></TrafficSwarmAction></TrafficAction>')
        self.assertEqual((swarm.central_entity, swarm.number_of_vehicles), ("Ego", 5))
        src = self.glob('<TrafficAction><TrafficSourceAction radius="5" rate="0.5"><Position>'
                        '<WorldPosition x="0" y="0"/></Position><TrafficDefinition name="d">'
                        '<VehicleCategoryDistribution><VehicleCategoryDistributionEntry '
                        'category="car" weight="1"/></VehicleCategoryDistribution>'
                        '</TrafficDefinition></TrafficSourceAction></TrafficAction>')
        self.assertEqual(src.definition.vehicle_categories, (("car", 1.0),))
        sink = self.glob('<TrafficAction><TrafficSinkAction radius="5"><Position><WorldPosition '
                         'x="9" y="0"/></Position></TrafficSinkAction></TrafficAction>')
        self.assertEqual(sink.radius, 5.0)


ROUTES = '''<?xml version="1.0"?>
<OpenSCENARIO><FileHeader revMajor="1" revMinor="0" date="2020-01-01T00:00:00" description="r" author="a"/>
  <Catalog name="Routes">
    <Route name="main" closed="false">
      <ParameterDeclarations><ParameterDeclaration name="End" parameterType="double" value="90"/></ParameterDeclarations>
      <Waypoint routeStrategy="fastest"><Position><LanePosition roadId="1" laneId="-1" s="0"/></Position></Waypoint>
      <Waypoint routeStrategy="fastest"><Position><LanePosition roadId="1" laneId="-1" s="$End"/></Position></Waypoint>
    </Route>
  </Catalog>
</OpenSCENARIO>'''

MANEUVERS = '''<?xml version="1.0"?>
<OpenSCENARIO><FileHeader revMajor="1" revMinor="0" date="2020-01-01T00:00:00" description="m" author="a"/>
  <Catalog name="Maneuvers">
    <Maneuver name="Brake">
      <ParameterDeclarations><ParameterDeclaration name="Who" parameterType="string" value="Ego"/></ParameterDeclarations>
      <Event name="Go" priority="overwrite">
        <Action name="Stop"><PrivateAction><LongitudinalAction><SpeedAction>
          <SpeedActionDynamics dynamicsShape="step" dynamicsDimension="time" value="0"/>
          <SpeedActionTarget><AbsoluteTargetSpeed value="0"/></SpeedActionTarget>
        </SpeedAction></LongitudinalAction></PrivateAction></Action>
        <StartTrigger><ConditionGroup><Condition name="c" delay="0" conditionEdge="none">
          <ByEntityCondition><TriggeringEntities triggeringEntitiesRule="any"><EntityRef entityRef="$Who"/></TriggeringEntities>
          <EntityCondition><SpeedCondition value="5" rule="greaterThan"/></EntityCondition></ByEntityCondition>
        </Condition></ConditionGroup></StartTrigger>
      </Event>
    </Maneuver>
  </Catalog>
</OpenSCENARIO>'''


class Catalogs(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.mkdtemp()
        self.addCleanup(shutil.rmtree, self.tmp)
        shutil.copy(os.path.join(os.path.dirname(PATH), "straight.xodr"), self.tmp)
        for name, body in (("routes.xosc", ROUTES), ("maneuvers.xosc", MANEUVERS)):
            with open(os.path.join(self.tmp, name), "w") as f:
                f.write(body)
        self.cats = ('<RouteCatalog><Directory path="."/></RouteCatalog>'
                     '<ManeuverCatalog><Directory path="."/></ManeuverCatalog>')

    def test_route_and_maneuver_references(self):
        story = act([("R", '<PrivateAction><RoutingAction><AssignRouteAction><CatalogReference '
                           'catalogName="Routes" entryName="main"><ParameterAssignments>'
                           '<ParameterAssignment parameterRef="End" value="120"/>'
                           '</ParameterAssignments></CatalogReference></AssignRouteAction>'
                           '</RoutingAction></PrivateAction>')],
                    extra='<CatalogReference catalogName="Maneuvers" entryName="Brake">'
                          '<ParameterAssignments><ParameterAssignment parameterRef="Who" '
                          'value="Target"/></ParameterAssignments></CatalogReference>')
        s = loads(text(story=story, catalogs=self.cats), os.path.join(self.tmp, "s.xosc"))
        group = s.stories[0].acts[0].groups[0]
        self.assertEqual([mn.path for mn in group.maneuvers], ["S::A::G::Brake", "S::A::G::M"])
        route = group.maneuvers[1].events[0].actions[0].spec
        self.assertEqual((route.name, route.waypoints[1].position.s, route.catalog.entry),
                         ("main", 120.0, "main"))
        cond = group.maneuvers[0].events[0].start_trigger.groups[0][0]
        self.assertEqual(cond.triggering, ("Target",))


if __name__ == "__main__":
    unittest.main()
