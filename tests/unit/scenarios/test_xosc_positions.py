"""The reader on issue 25's positions (kept symbolic: model_positions) and trajectory
shapes: Road, RelativeRoad, RelativeLane, RelativeObject, RelativeWorld, Geo, Route
positions; Clothoid, ClothoidSpline, Nurbs, closed trajectories."""

import math
import unittest

from test_xosc_support import load_text, private

from convoy_scenario import ScenarioError
from convoy_scenario import model as m


def teleport(position_xml):
    s = load_text(init=private('<TeleportAction><Position>%s</Position></TeleportAction>'
                               % position_xml))
    return s.init[0].spec.position


ROUTE = ('<Route name="r" closed="false"><Waypoint routeStrategy="shortest"><Position>'
         '<LanePosition roadId="1" laneId="-1" s="0"/></Position></Waypoint>'
         '<Waypoint routeStrategy="shortest"><Position><LanePosition roadId="1" laneId="-1" '
         's="100"/></Position></Waypoint></Route>')


class Positions(unittest.TestCase):
    def test_each_position(self):
        o = '<Orientation type="absolute" h="0.5"/>'
        self.assertEqual(teleport('<RoadPosition roadId="1" s="50" t="-1.5">%s</RoadPosition>'
                                  % o), m.RoadPosition("1", 50.0, -1.5, ("absolute", 0.5, 0, 0)))
        self.assertEqual(teleport('<RelativeRoadPosition entityRef="Target" ds="-20" dt="3.1"/>'),
                         m.RelativeRoadPosition("Target", -20.0, 3.1))
        self.assertEqual(teleport('<RelativeLanePosition entityRef="Target" dLane="-1" ds="-30"/>'),
                         m.RelativeLanePosition("Target", -1, -30.0))
        self.assertEqual(teleport('<RelativeLanePosition entityRef="Target" dLane="1" dsLane="5" '
                                  'offset="0.2"/>'),
                         m.RelativeLanePosition("Target", 1, None, 5.0, 0.2))
        self.assertEqual(teleport('<RelativeObjectPosition entityRef="Target" dx="1" dy="-0.6" '
                                  'dz="0.2">%s</RelativeObjectPosition>' % o),
                         m.RelativeObjectPosition("Target", 1.0, -0.6, 0.2,
                                                  ("absolute", 0.5, 0, 0)))
        self.assertEqual(teleport('<RelativeWorldPosition entityRef="Target" dx="3" dy="4"/>'),
                         m.RelativeWorldPosition("Target", 3.0, 4.0))
        geo = teleport('<GeoPosition latitudeDeg="57.7" longitudeDeg="12"/>')
        self.assertAlmostEqual(geo.latitude, math.radians(57.7))
        self.assertEqual(geo.as_dict()["type"], "geo")

    def test_route_position(self):
        p = teleport('<RoutePosition><RouteRef>%s</RouteRef><InRoutePosition>'
                     '<FromLaneCoordinates pathS="10" laneId="-1" laneOffset="0.3"/>'
                     '</InRoutePosition></RoutePosition>' % ROUTE)
        self.assertEqual((p.kind, p.path_s, p.lane_id, p.lane_offset), ("lane", 10.0, "-1", 0.3))
        self.assertEqual(p.route.name, "r")
        self.assertEqual(p.as_dict()["route"]["waypoints"][1]["position"]["s"], 100.0)
        p = teleport('<RoutePosition><RouteRef>%s</RouteRef><InRoutePosition>'
                     '<FromCurrentEntity entityRef="Target"/></InRoutePosition></RoutePosition>'
                     % ROUTE)
        self.assertEqual((p.kind, p.entity), ("entity", "Target"))

    def test_bad_positions(self):
        for xml, message in (
                ('<RelativeLanePosition entityRef="Target" dLane="1" ds="1" dsLane="2"/>',
                 "<RelativeLanePosition> needs exactly one of the attributes ds and dsLane"),
                ('<RelativeObjectPosition entityRef="Nobody" dx="1" dy="0"/>',
                 "<RelativeObjectPosition> entityRef: no entity 'Nobody' (entities: Ego, Target)"),
                ('<RoadPosition roadId="1" s="1"/>', "<RoadPosition> needs attribute t")):
            with self.subTest(xml=xml):
                with self.assertRaises(ScenarioError) as e:
                    teleport(xml)
                self.assertIn(message, str(e.exception))


def follow(shape_xml, closed="false", timing='<None/>'):
    s = load_text(init=private(
        '<RoutingAction><FollowTrajectoryAction initialDistanceOffset="2"><TrajectoryRef>'
        '<Trajectory name="t" closed="%s"><Shape>%s</Shape></Trajectory></TrajectoryRef>'
        '<TimeReference>%s</TimeReference><TrajectoryFollowingMode followingMode="position"/>'
        '</FollowTrajectoryAction></RoutingAction>' % (closed, shape_xml, timing)))
    return s.init[0].spec


def point(x, y, extra=""):
    return '<Position><WorldPosition x="%g" y="%g"/></Position>' % (x, y)


class Trajectories(unittest.TestCase):
    def test_clothoid(self):
        f = follow('<Clothoid curvature="0.01" curvaturePrime="0" length="50" startTime="0">'
                   '<Position><RelativeObjectPosition entityRef="Target" dx="0" dy="0"/>'
                   '</Position></Clothoid>')
        self.assertEqual(f.shape, m.Clothoid(0.01, 0.0, 50.0, m.RelativeObjectPosition(
            "Target", 0.0, 0.0), 0.0))
        self.assertEqual((f.vertices, f.following_mode, f.initial_distance_offset),
                         ((), "position", 2.0))
        old = follow('<Clothoid curvature="0" curvatureDot="0.001" length="5">%s</Clothoid>'
                     % point(0, 0))
        self.assertEqual(old.shape.curvature_prime, 0.001)

    def test_clothoid_spline(self):
        f = follow('<ClothoidSpline><ClothoidSplineSegment curvatureStart="0.1" curvatureEnd="0" '
                   'length="10"><PositionStart><WorldPosition x="1" y="2"/></PositionStart>'
                   '</ClothoidSplineSegment><ClothoidSplineSegment curvatureStart="0" '
                   'curvatureEnd="0" length="5" hOffset="0.1"/></ClothoidSpline>')
        a, b = f.shape.segments
        self.assertEqual((a.position_start, b.position_start, b.h_offset),
                         (m.WorldPosition(1.0, 2.0), None, 0.1))

    def test_nurbs(self):
        cps = "".join('<ControlPoint time="%d" weight="1">%s</ControlPoint>' % (i, point(i, i))
                      for i in range(4))
        knots = "".join('<Knot value="%g"/>' % k for k in (0, 0, 0, 1, 2, 2, 2))
        f = follow('<Nurbs order="3">%s%s</Nurbs>' % (cps, knots),
                   timing='<Timing domainAbsoluteRelative="relative" scale="1" offset="0"/>')
        self.assertEqual((f.shape.order, len(f.shape.control_points), f.shape.knots[-1]),
                         (3, 4, 2.0))
        with self.assertRaises(ScenarioError) as e:
            follow('<Nurbs order="3">%s<Knot value="0"/></Nurbs>' % cps)
        self.assertIn("<Nurbs> needs 7 <Knot>s (control points + order), got 1", str(e.exception))

    def test_closed_polyline_with_lane_vertices(self):
        f = follow('<Polyline><Vertex><Position><LanePosition roadId="1" laneId="-1" s="0"/>'
                   '</Position></Vertex><Vertex>%s</Vertex></Polyline>' % point(5, 0),
                   closed="true")
        self.assertTrue(f.closed)
        self.assertEqual(f.vertices[0].position, m.LanePosition("1", "-1", 0.0))


if __name__ == "__main__":
    unittest.main()
