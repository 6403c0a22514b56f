#!/usr/bin/python3
"""Writes the scenario suite's .xosc files (benchmarks/suite, docs/scenarios.md "The suite"),
deterministically: edit this script rather than the files, then run it
(/usr/bin/python3 benchmarks/suite/make_suite.py). Every scenario is OpenSCENARIO 1.1 over the
project's city map (experiments/city_traffic/city.xodr) or the Parkring
(experiments/autonomous_driving/parkring.xodr), with ParameterDeclarations for what varies and
CatalogReferences into catalogs/ (vehicles.xosc, pedestrians.xosc), as esmini's scenarios are
written. The ego is the entity `Ego` (the smart car); its route is the lane it starts on,
followed for $RouteLength m (straight on at junctions), unless it has an AssignRouteAction.

The city: road 1 runs east from x = -250 (s = x + 250) to junction 100 at x = 0, road 2 on to
junction 200 at x = 200; lanes -1 / -2 eastbound (y = -1.75 / -5.25), 1 / 2 westbound, sidewalks
-3 / 3 (y = -8.25 / 8.25); road 4 leaves junction 100 north, road 5 south (lanes -1 northbound).
"""
import os

HERE = os.path.dirname(os.path.abspath(__file__))
CITY = "../../experiments/city_traffic/city.xodr"
PARKRING = "../../experiments/autonomous_driving/parkring.xodr"


# --- XML pieces ---------------------------------------------------------------------------------

def params(p):
    out = ["  <ParameterDeclarations>"]
    for name, (ptype, value) in p.items():
        out.append('    <ParameterDeclaration name="%s" parameterType="%s" value="%s"/>' % (name, ptype, value))
    out.append("  </ParameterDeclarations>")
    return "\n".join(out)


# Road users other than the ego are Convoy's agents (vehicle_agent, pedestrian_agent): their
# own AI drives them between the scenario's actions (docs/scenarios.md, "Controllers")
AGENT = ('      <ObjectController><Controller name="convoy.agent"><Properties/></Controller>'
         '</ObjectController>\n')


def vehicle(name, entry, assign=None, agent=True, props=None):
    """props: the agent controller's Properties ({"convoy.v0": "0"}: its AI's desired speed)."""
    a = ""
    if assign:
        a = "\n        <ParameterAssignments>%s</ParameterAssignments>\n      " % "".join(
            '<ParameterAssignment parameterRef="%s" value="%s"/>' % kv for kv in assign.items())
    return ('    <ScenarioObject name="%s">\n      <CatalogReference catalogName="SuiteVehicles" entryName="%s">%s'
            '</CatalogReference>\n%s    </ScenarioObject>' % (name, entry, a, _agent(props) if agent else ""))


def _agent(props):
    if not props:
        return AGENT
    return AGENT.replace("<Properties/>", "<Properties>%s</Properties>" % "".join(
        '<Property name="%s" value="%s"/>' % kv for kv in sorted(props.items())))


def pedestrian(name, entry):
    return ('    <ScenarioObject name="%s">\n      <CatalogReference catalogName="SuitePedestrians" entryName="%s"/>\n'
            '%s    </ScenarioObject>' % (name, entry, AGENT))


def lane_pos(road, lane, s, offset="0"):
    return '<LanePosition roadId="%s" laneId="%s" s="%s" offset="%s"/>' % (road, lane, s, offset)


def world_pos(x, y, h=None):
    return '<WorldPosition x="%s" y="%s"%s/>' % (x, y, ' h="%s"' % h if h is not None else "")


def teleport(pos):
    return "<PrivateAction><TeleportAction><Position>%s</Position></TeleportAction></PrivateAction>" % pos


def hold(pos_x, pos_y, h, until="$Duration"):
    """Stand still at (x, y) heading h until `until` s: a timed trajectory of two equal vertices
    (it controls the actor's both domains, so its own AI does not move it)."""
    v = '<Vertex time="%s"><Position><WorldPosition x="%s" y="%s" h="%s"/></Position></Vertex>'
    return ('<PrivateAction><RoutingAction><FollowTrajectoryAction><Trajectory name="Hold" closed="false">'
            '<Shape><Polyline>%s%s</Polyline></Shape></Trajectory><TimeReference><Timing '
            'domainAbsoluteRelative="absolute" scale="1" offset="0"/></TimeReference>'
            '<TrajectoryFollowingMode followingMode="position"/></FollowTrajectoryAction></RoutingAction>'
            '</PrivateAction>' % (v % ("0", pos_x, pos_y, h), v % (until, pos_x, pos_y, h)))


def speed(value, shape="step", dim="time", rate="0"):
    return ('<PrivateAction><LongitudinalAction><SpeedAction>'
            '<SpeedActionDynamics dynamicsShape="%s" dynamicsDimension="%s" value="%s"/>'
            '<SpeedActionTarget><AbsoluteTargetSpeed value="%s"/></SpeedActionTarget>'
            '</SpeedAction></LongitudinalAction></PrivateAction>' % (shape, dim, rate, value))


def lane_change(target, time, relative_to=None):
    tgt = ('<RelativeTargetLane entityRef="%s" value="0"/>' % relative_to if relative_to
           else '<AbsoluteTargetLane value="%s"/>' % target)
    return ('<PrivateAction><LateralAction><LaneChangeAction targetLaneOffset="0">'
            '<LaneChangeActionDynamics dynamicsShape="sinusoidal" dynamicsDimension="time" value="%s"/>'
            '<LaneChangeTarget>%s</LaneChangeTarget></LaneChangeAction></LateralAction></PrivateAction>'
            % (time, tgt))


def walk(name, points, speed_param="$WalkSpeed"):
    """Walk the polyline at speed_param m/s from the event's start: a timed trajectory (relative
    timing), which controls the walker's both domains, so its own AI (gap acceptance) does not
    stop it at the kerb."""
    verts, t, prev = [], 0.0, None
    for x, y in points:
        if prev is not None:
            t += abs(float(y) - float(prev[1])) if prev[0] == x else 0.0
        time = "0" if prev is None else "${%g / %s}" % (t, speed_param)
        verts.append('<Vertex time="%s"><Position>%s</Position></Vertex>' % (time, world_pos(x, y)))
        prev = (x, y)
    return ('<PrivateAction><RoutingAction><FollowTrajectoryAction><Trajectory name="%s" closed="false">'
            '<Shape><Polyline>%s</Polyline></Shape></Trajectory><TimeReference><Timing '
            'domainAbsoluteRelative="relative" scale="1" offset="0"/></TimeReference>'
            '<TrajectoryFollowingMode followingMode="position"/></FollowTrajectoryAction></RoutingAction>'
            '</PrivateAction>' % (name, "".join(verts)))


def route(name, positions):
    wps = "".join('<Waypoint routeStrategy="shortest"><Position>%s</Position></Waypoint>' % p for p in positions)
    return ('<PrivateAction><RoutingAction><AssignRouteAction><Route name="%s" closed="false">%s</Route>'
            '</AssignRouteAction></RoutingAction></PrivateAction>' % (name, wps))


def environment(name, fog=None, rain=None, snow=None, time="2026-06-01T12:00:00", friction="1.0"):
    w = []
    if fog is not None:
        w.append('<Fog visualRange="%s"/>' % fog)
    if rain is not None:
        w.append('<Precipitation precipitationType="rain" intensity="%s"/>' % rain)
    elif snow is not None:
        w.append('<Precipitation precipitationType="snow" intensity="%s"/>' % snow)
    else:
        w.append('<Precipitation precipitationType="dry" intensity="0"/>')
    return ('<GlobalAction><EnvironmentAction><Environment name="%s">'
            '<TimeOfDay animation="false" dateTime="%s"/><Weather cloudState="%s">%s</Weather>'
            '<RoadCondition frictionScaleFactor="%s"/></Environment></EnvironmentAction></GlobalAction>'
            % (name, time, "rainy" if rain or snow else ("overcast" if fog else "free"), "".join(w), friction))


# conditions
def sim_time(t):
    return ('<Condition name="At%s" delay="0" conditionEdge="rising"><ByValueCondition>'
            '<SimulationTimeCondition value="%s" rule="greaterOrEqual"/></ByValueCondition></Condition>'
            % (str(t).replace("$", "").replace(".", "_"), t))


def near(trigger, ref, value, name="Near"):
    """trigger's reference point within value m of ref's (euclidean)."""
    return ('<Condition name="%s" delay="0" conditionEdge="rising"><ByEntityCondition>'
            '<TriggeringEntities triggeringEntitiesRule="any"><EntityRef entityRef="%s"/></TriggeringEntities>'
            '<EntityCondition><RelativeDistanceCondition entityRef="%s" value="%s" freespace="false" '
            'relativeDistanceType="euclidianDistance" coordinateSystem="entity" rule="lessThan"/>'
            '</EntityCondition></ByEntityCondition></Condition>' % (name, trigger, ref, value))


def headway(trigger, ref, value, name="Ahead"):
    return ('<Condition name="%s" delay="0" conditionEdge="rising"><ByEntityCondition>'
            '<TriggeringEntities triggeringEntitiesRule="any"><EntityRef entityRef="%s"/></TriggeringEntities>'
            '<EntityCondition><TimeHeadwayCondition entityRef="%s" value="%s" freespace="true" '
            'coordinateSystem="entity" relativeDistanceType="longitudinal" rule="greaterThan"/>'
            '</EntityCondition></ByEntityCondition></Condition>' % (name, trigger, ref, value))


def ttc(trigger, ref, value, name="TtcLow"):
    return ('<Condition name="%s" delay="0" conditionEdge="rising"><ByEntityCondition>'
            '<TriggeringEntities triggeringEntitiesRule="any"><EntityRef entityRef="%s"/></TriggeringEntities>'
            '<EntityCondition><TimeToCollisionCondition value="%s" freespace="true" rule="lessThan" '
            'relativeDistanceType="longitudinal" coordinateSystem="entity"><TimeToCollisionConditionTarget>'
            '<EntityRef entityRef="%s"/></TimeToCollisionConditionTarget></TimeToCollisionCondition>'
            '</EntityCondition></ByEntityCondition></Condition>' % (name, trigger, value, ref))


def stopped(entity, delay, name="Stopped"):
    return ('<Condition name="%s" delay="%s" conditionEdge="rising"><ByEntityCondition>'
            '<TriggeringEntities triggeringEntitiesRule="any"><EntityRef entityRef="%s"/></TriggeringEntities>'
            '<EntityCondition><SpeedCondition value="0.05" rule="lessThan"/></EntityCondition>'
            '</ByEntityCondition></Condition>' % (name, delay, entity))


def after(event, name="After"):
    return ('<Condition name="%s" delay="0" conditionEdge="none"><ByValueCondition>'
            '<StoryboardElementStateCondition storyboardElementType="event" storyboardElementRef="%s" '
            'state="endTransition"/></ByValueCondition></Condition>' % (name, event))


def reach(entity, x, y, tol=2.0, name="Reached"):
    return ('<Condition name="%s" delay="0" conditionEdge="rising"><ByEntityCondition>'
            '<TriggeringEntities triggeringEntitiesRule="any"><EntityRef entityRef="%s"/></TriggeringEntities>'
            '<EntityCondition><ReachPositionCondition tolerance="%s"><Position>%s</Position>'
            '</ReachPositionCondition></EntityCondition></ByEntityCondition></Condition>'
            % (name, entity, tol, world_pos(x, y)))


def event(name, action, trigger=None, priority="parallel"):
    t = ("<StartTrigger><ConditionGroup>%s</ConditionGroup></StartTrigger>" % trigger) if trigger else ""
    return ('            <Event name="%s" priority="%s"><Action name="%sAction">%s</Action>%s</Event>'
            % (name, priority, name, action, t))


def group(actor, events):
    return ('        <ManeuverGroup name="%sGroup" maximumExecutionCount="1">\n'
            '          <Actors selectTriggeringEntities="false"><EntityRef entityRef="%s"/></Actors>\n'
            '          <Maneuver name="%sManeuver">\n%s\n          </Maneuver>\n        </ManeuverGroup>'
            % (actor, actor, actor, "\n".join(events)))


def scenario(description, p, entities, init, groups, xodr=CITY):
    """init: {entity or None (global): [actions]}; groups: [group xml]."""
    p = dict(p)
    p.setdefault("Duration", ("double", "40"))
    inits = []
    for ent, actions in init.items():
        if ent is None:
            inits += ["        %s" % a for a in actions]
        else:
            inits.append('        <Private entityRef="%s">\n%s\n        </Private>' % (
                ent, "\n".join("          %s" % a for a in actions)))
    story = ""
    if groups:
        story = ('    <Story name="Story">\n      <Act name="Act">\n%s\n      </Act>\n    </Story>\n'
                 % "\n".join(groups))
    return """<?xml version="1.0" encoding="UTF-8"?>
<!-- %s
     Generated by benchmarks/suite/make_suite.py. -->
<OpenSCENARIO>
  <FileHeader revMajor="1" revMinor="1" date="2026-11-25T12:00:00" description="%s" author="Convoy"/>
%s
  <CatalogLocations>
    <VehicleCatalog><Directory path="catalogs"/></VehicleCatalog>
    <PedestrianCatalog><Directory path="catalogs"/></PedestrianCatalog>
  </CatalogLocations>
  <RoadNetwork>
    <LogicFile filepath="%s"/>
  </RoadNetwork>
  <Entities>
%s
  </Entities>
  <Storyboard>
    <Init>
      <Actions>
%s
      </Actions>
    </Init>
%s    <StopTrigger>
      <ConditionGroup>
        <Condition name="Timeout" delay="0" conditionEdge="rising">
          <ByValueCondition><SimulationTimeCondition value="$Duration" rule="greaterOrEqual"/></ByValueCondition>
        </Condition>
      </ConditionGroup>
    </StopTrigger>
  </Storyboard>
</OpenSCENARIO>
""" % (description, description.split(":")[0], params(p), xodr, "\n".join(entities), "\n".join(inits), story)


# --- the scenarios --------------------------------------------------------------------------------

EGO = vehicle("Ego", "smart_car", agent=False)


def ego_init(s="$EgoS", lane="-1", road="1"):
    return [teleport(lane_pos(road, lane, s))]


def cut_in(hw="0.6", change="3", end_speed="6", speed_="12", weather=None, desc=""):
    p = {"EgoS": ("double", "30"), "CutterSpeed": ("double", speed_), "CutterEndSpeed": ("double", end_speed),
         "Headway": ("double", hw), "LaneChangeTime": ("double", change),
         "RouteLength": ("double", "150"), "Duration": ("double", "30")}
    init = {"Ego": ego_init(), "Cutter": [teleport(lane_pos("1", "-2", "${$EgoS - 12}")), speed("$CutterSpeed")]}
    if weather:
        init[None] = [weather]
    g = group("Cutter", [
        event("KeepSpeed", speed("$CutterSpeed")),
        event("CutIn", lane_change(None, "$LaneChangeTime", relative_to="Ego"), headway("Ego", "Cutter", "$Headway", "CutterAhead")),
        event("SlowDown", speed("$CutterEndSpeed", "linear", "time", "10"), after("CutIn", "CutInDone")),
    ])
    return scenario("Cut-in%s: a sedan in the left lane overtakes the ego and, once its rear is $Headway s "
                    "of the ego's travel ahead, changes into the ego's lane in $LaneChangeTime s, then "
                    "slows to $CutterEndSpeed m/s" % desc, p,
                    [EGO, vehicle("Cutter", "sedan", {"Model": "sedan_blue"})], init, [g])


def lead_brake(gap="25", decel="-6", lead_speed="8", weather=None, desc=""):
    p = {"EgoS": ("double", "30"), "Gap": ("double", gap), "LeadSpeed": ("double", lead_speed),
         "Deceleration": ("double", decel), "BrakeAt": ("double", "8"), "RouteLength": ("double", "150"),
         "Duration": ("double", "35")}
    init = {"Ego": ego_init(), "Lead": [teleport(lane_pos("1", "-1", "${$EgoS + $Gap}")), speed("$LeadSpeed")]}
    if weather:
        init[None] = [weather]
    g = group("Lead", [
        event("Cruise", speed("$LeadSpeed")),
        event("Brake", speed("0", "linear", "rate", "$Deceleration"), sim_time("$BrakeAt"), "overwrite"),
        event("DriveOff", speed("$LeadSpeed", "linear", "rate", "2"), stopped("Lead", "3", "LeadStopped")),
    ])
    return scenario("Leading vehicle brakes hard%s: a car $Gap m ahead of the ego in its lane at $LeadSpeed m/s "
                    "brakes at $Deceleration m/s^2 to a stop at t = $BrakeAt s, waits 3 s and drives off" % desc,
                    p, [EGO, vehicle("Lead", "hatchback")], init, [g])


def following(lead_speed="6", gap="30", weather=None, desc="", lead="suv"):
    p = {"EgoS": ("double", "30"), "Gap": ("double", gap), "LeadSpeed": ("double", lead_speed),
         "RouteLength": ("double", "150"), "Duration": ("double", "40")}
    init = {"Ego": ego_init(), "Lead": [teleport(lane_pos("1", "-1", "${$EgoS + $Gap}")), speed("$LeadSpeed")]}
    if weather:
        init[None] = [weather]
    g = group("Lead", [event("Cruise", speed("$LeadSpeed"))])
    return scenario("Following%s: a slower vehicle ($LeadSpeed m/s) $Gap m ahead in the ego's lane" % desc,
                    p, [EGO, vehicle("Lead", lead)], init, [g])


def jaywalker(entry="adult", walk_speed="1.6", trigger_m="30", x="-100", weather=None, desc="", north=True):
    p = {"EgoS": ("double", "40"), "WalkSpeed": ("double", walk_speed), "TriggerDistance": ("double", trigger_m),
         "CrossX": ("double", x), "RouteLength": ("double", "150"), "Duration": ("double", "35")}
    y0, y1 = ("8.25", "-8.25") if north else ("-8.25", "8.25")
    h = "-1.5708" if north else "1.5708"
    init = {"Ego": ego_init(), "Walker": [teleport(world_pos("$CrossX", y0, h)), hold("$CrossX", y0, h)]}
    if weather:
        init[None] = [weather]
    g = group("Walker", [
        event("Cross", walk("Crossing", [("$CrossX", y0), ("$CrossX", y1)]), near("Ego", "Walker", "$TriggerDistance", "EgoNear")),
    ])
    return scenario("Jaywalker%s: a pedestrian crosses the road mid-block at x = $CrossX at $WalkSpeed m/s when "
                    "the ego is $TriggerDistance m away" % desc, p, [EGO, pedestrian("Walker", entry)], init, [g])


def pedestrian_behind_parked(weather=None, desc=""):
    p = {"EgoS": ("double", "40"), "WalkSpeed": ("double", "1.8"), "TriggerDistance": ("double", "25"),
         "ParkedS": ("double", "150"), "RouteLength": ("double", "150"), "Duration": ("double", "35")}
    init = {"Ego": ego_init(),
            "Parked": [teleport(lane_pos("1", "-2", "$ParkedS")), hold("${$ParkedS - 250}", "-5.25", "0")],
            "Walker": [teleport(world_pos("${$ParkedS - 247}", "-8.0", "1.5708")),
                       hold("${$ParkedS - 247}", "-8.0", "1.5708")]}
    if weather:
        init[None] = [weather]
    g = group("Walker", [
        event("StepOut", walk("StepOut", [("${$ParkedS - 247}", "-8.0"), ("${$ParkedS - 247}", "3.0")]),
              near("Ego", "Walker", "$TriggerDistance", "EgoNear")),
    ])
    ent = [EGO, vehicle("Parked", "van"), pedestrian("Walker", "child")]
    text = scenario("Pedestrian steps out behind a parked car%s: a child walks out from behind a van parked "
                    "in the right lane, into the ego's lane, when the ego is $TriggerDistance m away" % desc,
                    p, ent, init, [g])
    return text


def stopped_vehicle(desc=""):
    # The ego's route is its own lane (1:-1 onward, straight on through junction 100): the
    # reference agent passes the broken-down car by a lane change of its own (its planner's MOBIL
    # check, python/convoy_traffic/lane_change.py), into the right lane once the car coming from
    # behind there has gone by. The broken-down car's AI wants no speed (convoy.v0 0): it stands
    # all run (a hold trajectory alone holds it only while the storyboard runs). 60 s: past the
    # car, the ego reaches junction 100 on its approach's red and waits for the green at 40 s.
    p = {"EgoS": ("double", "30"), "StoppedS": ("double", "110"), "PasserSpeed": ("double", "8.5"),
         "RouteLength": ("double", "180"), "Duration": ("double", "60")}
    init = {"Ego": ego_init(),
            "Stopped": [teleport(lane_pos("1", "-1", "$StoppedS")), hold("${$StoppedS - 250}", "-1.75", "0")],
            "Passer": [teleport(lane_pos("1", "-2", "0")), speed("$PasserSpeed")]}
    return scenario("Stopped vehicle ahead%s: a broken-down car stands in the ego's lane; a car in the right "
                    "lane comes from behind at $PasserSpeed m/s; the ego's route stays in its lane" % desc, p,
                    [EGO, vehicle("Stopped", "sedan", {"Model": "sedan_red"}, props={"convoy.v0": "0"}),
                     vehicle("Passer", "sedan", {"Model": "sedan_white"})], init, [])


def red_light(desc=""):
    # junction 100's approaches from the west are green for 15 s from t = 0 (then yellow 3 s,
    # all red 2 s, the other road's 20 s): from s = 20 the ego reaches the stop line at ~27 s
    p = {"EgoS": ("double", "20"), "RouteLength": ("double", "260"), "Duration": ("double", "60")}
    init = {"Ego": ego_init()}
    return scenario("Red light%s: the ego reaches junction 100 on its approach's red (the traffic_lights "
                    "engine's fixed program: 15 s green, 3 s yellow, 2 s all red) and must wait" % desc,
                    p, [EGO], init, [])


def left_turn(desc=""):
    p = {"EgoS": ("double", "170"), "OncomingS": ("double", "60"), "OncomingSpeed": ("double", "9"),
         "RouteLength": ("double", "120"), "Duration": ("double", "40")}
    init = {"Ego": ego_init() + [route("LeftTurn", [lane_pos("1", "-1", "$EgoS"), lane_pos("4", "-1", "40")])],
            "Oncoming": [teleport(lane_pos("2", "1", "$OncomingS")), speed("$OncomingSpeed")],
            "Oncoming2": [teleport(lane_pos("2", "1", "${$OncomingS + 30}")), speed("$OncomingSpeed")]}
    g = group("Oncoming", [event("Cruise", speed("$OncomingSpeed"))])
    return scenario("Unprotected left turn across traffic%s: the ego turns left at junction 100 into road 4 "
                    "while two cars come the other way at $OncomingSpeed m/s" % desc, p,
                    [EGO, vehicle("Oncoming", "suv"), vehicle("Oncoming2", "sedan", {"Model": "sedan_white"})], init, [g])


def merge(desc=""):
    p = {"EgoS": ("double", "170"), "MergerS": ("double", "70"), "MergerSpeed": ("double", "8"),
         "RouteLength": ("double", "140"), "Duration": ("double", "40")}
    init = {"Ego": ego_init(),
            "Merger": [teleport(lane_pos("5", "-1", "$MergerS")), speed("$MergerSpeed"),
                       route("RightTurn", [lane_pos("5", "-1", "$MergerS"), lane_pos("2", "-1", "30")])]}
    return scenario("Merge%s: a car from the south road turns right into the ego's lane at junction 100 "
                    "just ahead of the ego" % desc, p, [EGO, vehicle("Merger", "van")], init, [])


def cyclist(desc=""):
    p = {"EgoS": ("double", "30"), "Gap": ("double", "25"), "BikeSpeed": ("double", "4"),
         "RouteLength": ("double", "140"), "Duration": ("double", "45")}
    init = {"Ego": ego_init(), "Cyclist": [teleport(lane_pos("1", "-1", "${$EgoS + $Gap}")), speed("$BikeSpeed")]}
    g = group("Cyclist", [event("Ride", speed("$BikeSpeed"))])
    return scenario("Cyclist%s: a cyclist rides at $BikeSpeed m/s $Gap m ahead in the ego's lane" % desc, p,
                    [EGO, vehicle("Cyclist", "bicycle")], init, [g])


def parkring_following():
    p = {"EgoS": ("double", "20"), "Gap": ("double", "30"), "LeadSpeed": ("double", "6"),
         "RouteLength": ("double", "160"), "Duration": ("double", "40")}
    init = {"Ego": ego_init(road="1"), "Lead": [teleport(lane_pos("1", "-1", "${$EgoS + $Gap}")), speed("$LeadSpeed")]}
    g = group("Lead", [event("Cruise", speed("$LeadSpeed"))])
    return scenario("Following on the Parkring: a slower car ($LeadSpeed m/s) $Gap m ahead of the ego",
                    p, [EGO, vehicle("Lead", "hatchback")], init, [g], xodr=PARKRING)


RAIN = environment("Rain", rain="0.7", friction="0.6")
FOG = environment("Fog", fog="60")
NIGHT_RAIN = environment("NightRain", rain="0.5", time="2026-11-20T22:30:00", friction="0.6")
SNOW = environment("Snow", snow="0.5", friction="0.3")

SUITE = {
    "cut_in": cut_in(),
    "cut_in_close": cut_in(hw="0.3", change="2", desc=" (close)"),
    "cut_in_slow": cut_in(end_speed="3", speed_="11", desc=" (then slows to a crawl)"),
    "lead_brake": lead_brake(),
    "lead_brake_close": lead_brake(gap="15", decel="-8", desc=" (close, -8 m/s^2)"),
    "pedestrian_behind_parked_car": pedestrian_behind_parked(),
    "jaywalker": jaywalker(),
    "jaywalker_child": jaywalker(entry="child", walk_speed="2.2", trigger_m="22", x="-90", north=False,
                                 desc=" (a running child, from the right)"),
    "left_turn": left_turn(),
    "red_light": red_light(),
    "merge": merge(),
    "following": following(),
    "stopped_vehicle": stopped_vehicle(),
    "cyclist": cyclist(),
    "following_rain": following(weather=RAIN, desc=" in rain"),
    "cut_in_fog": cut_in(weather=FOG, desc=" in fog (60 m)"),
    "jaywalker_night_rain": jaywalker(weather=NIGHT_RAIN, desc=" at night in rain"),
    "lead_brake_fog": lead_brake(weather=FOG, desc=" in fog (60 m)"),
    "lead_brake_snow": lead_brake(weather=SNOW, decel="-5", desc=" in snow"),
    "following_truck": following(lead_speed="5", gap="35", lead="truck", desc=" a truck"),
    "parkring_following": parkring_following(),
}


def main():
    for name, text in sorted(SUITE.items()):
        with open(os.path.join(HERE, name + ".xosc"), "w") as f:
            f.write(text)
    print("%d scenarios written to %s" % (len(SUITE), HERE))


if __name__ == "__main__":
    main()
