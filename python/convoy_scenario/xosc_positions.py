"""Positions, routes and trajectories for the reader (xosc.py). Positions are kept symbolic
(model_positions): the player resolves those relative to entities, roads and routes."""

import math

from . import model as m
from .model_positions import POSITION_TAGS

ROUTE_STRATEGIES = ("fastest", "shortest", "leastIntersections", "random")


class PositionsReader:
    def position(self, node, scope):
        """The position inside node (a <Position>, or an element whose child is the
        position: PositionStart, TargetPosition, TargetPositionMaster)."""
        p = node.only_child(POSITION_TAGS)
        return getattr(self, "_pos_" + p.tag)(p, scope)

    def orientation(self, p, scope):
        o = p.find("Orientation")
        if o is None:
            return None
        return (self.value(o, "type", scope, "enum", "relative", ("relative", "absolute")),
                self.number(o, "h", scope, 0.0), self.number(o, "p", scope, 0.0),
                self.number(o, "r", scope, 0.0))

    def lane_id(self, node, attr, scope, default=None):
        lane = self.value(node, attr, scope, default=default)
        if lane is None:
            return None
        try:
            return str(int(lane))
        except ValueError:
            raise node.error("%s: expected an integer lane id, got %r" % (attr, lane)) from None

    def road_id(self, node, scope):
        road = self.value(node, "roadId", scope)
        try:   # a double parameter ("1.0") names road "1"
            return str(int(float(road))) if float(road) == int(float(road)) else road
        except (ValueError, OverflowError):
            return road

    def _pos_WorldPosition(self, p, scope):
        return m.WorldPosition(self.number(p, "x", scope), self.number(p, "y", scope),
                               self.number(p, "z", scope, 0.0), self.number(p, "h", scope, None),
                               self.number(p, "p", scope, 0.0), self.number(p, "r", scope, 0.0))

    def _pos_LanePosition(self, p, scope):
        return m.LanePosition(self.road_id(p, scope), self.lane_id(p, "laneId", scope),
                              self.number(p, "s", scope), self.number(p, "offset", scope, 0.0),
                              self.orientation(p, scope))

    def _pos_RoadPosition(self, p, scope):
        return m.RoadPosition(self.road_id(p, scope), self.number(p, "s", scope),
                              self.number(p, "t", scope), self.orientation(p, scope))

    def _pos_RelativeWorldPosition(self, p, scope):
        return m.RelativeWorldPosition(self.entity_ref(p, scope), self.number(p, "dx", scope),
                                       self.number(p, "dy", scope),
                                       self.number(p, "dz", scope, 0.0), self.orientation(p, scope))

    def _pos_RelativeObjectPosition(self, p, scope):
        return m.RelativeObjectPosition(self.entity_ref(p, scope), self.number(p, "dx", scope),
                                        self.number(p, "dy", scope),
                                        self.number(p, "dz", scope, 0.0),
                                        self.orientation(p, scope))

    def _pos_RelativeRoadPosition(self, p, scope):
        return m.RelativeRoadPosition(self.entity_ref(p, scope), self.number(p, "ds", scope),
                                      self.number(p, "dt", scope), self.orientation(p, scope))

    def _pos_RelativeLanePosition(self, p, scope):
        ds, ds_lane = self.number(p, "ds", scope, None), self.number(p, "dsLane", scope, None)
        if (ds is None) == (ds_lane is None):
            raise p.error("needs exactly one of the attributes ds and dsLane")
        return m.RelativeLanePosition(self.entity_ref(p, scope),
                                      self.value(p, "dLane", scope, "integer"), ds, ds_lane,
                                      self.number(p, "offset", scope, 0.0),
                                      self.orientation(p, scope))

    def _pos_GeoPosition(self, p, scope):
        if "latitudeDeg" in p.attrib:
            lat = math.radians(self.number(p, "latitudeDeg", scope))
            lon = math.radians(self.number(p, "longitudeDeg", scope))
        else:
            lat, lon = self.number(p, "latitude", scope), self.number(p, "longitude", scope)
        alt = self.number(p, "altitude", scope, None)
        if alt is None:
            alt = self.number(p, "height", scope, 0.0)
        return m.GeoPosition(lat, lon, alt, self.orientation(p, scope))

    def _pos_RoutePosition(self, p, scope):
        ref = p.need("RouteRef").only_child(("Route", "CatalogReference"))
        route = self.route(ref, scope)
        where = p.need("InRoutePosition").only_child(
            ("FromCurrentEntity", "FromRoadCoordinates", "FromLaneCoordinates"))
        o = self.orientation(p, scope)
        if where.tag == "FromCurrentEntity":
            return m.RoutePosition(route, "entity", entity=self.entity_ref(where, scope),
                                   orientation=o)
        if where.tag == "FromRoadCoordinates":
            return m.RoutePosition(route, "road", path_s=self.number(where, "pathS", scope),
                                   t=self.number(where, "t", scope), orientation=o)
        return m.RoutePosition(route, "lane", path_s=self.number(where, "pathS", scope),
                               lane_id=self.lane_id(where, "laneId", scope),
                               lane_offset=self.number(where, "laneOffset", scope, 0.0),
                               orientation=o)

    def _pos_TrajectoryPosition(self, p, scope):
        ref = p.need("TrajectoryRef").only_child(("Trajectory", "CatalogReference"))
        return m.TrajectoryPosition(self.trajectory(ref, scope)[0], self.number(p, "s", scope),
                                    self.number(p, "t", scope, 0.0), self.orientation(p, scope))

    # --- routes ----------------------------------------------------------------------------

    def route(self, node, scope):
        """A Route element or a CatalogReference to one: a model.Route."""
        source = None
        if node.tag == "CatalogReference":
            node, rscope, source = self.catalog_entry(node, scope, ("Route",))
        else:
            rscope = self.declare(node.find("ParameterDeclarations"), scope)
        points = node.findall("Waypoint")
        if len(points) < 2:
            raise node.error("needs at least 2 <Waypoint>s, got %d" % len(points))
        return m.Route(self.value(node, "name", rscope), self.boolean(node, "closed", rscope),
                       tuple(m.Waypoint(self.position(w.need("Position"), rscope),
                                        self.value(w, "routeStrategy", rscope, "enum",
                                                   choices=ROUTE_STRATEGIES))
                             for w in points), source)

    # --- trajectories ----------------------------------------------------------------------

    def trajectory(self, node, scope, timed=False):
        """A Trajectory element or a CatalogReference to one: (model.Trajectory, scope,
        CatalogSource or None). timed: vertex times are required (a Timing reference)."""
        source = None
        if node.tag == "CatalogReference":
            node, tscope, source = self.catalog_entry(node, scope, ("Trajectory",))
        else:
            tscope = self.declare(node.find("ParameterDeclarations"), scope)
        shape = node.need("Shape").only_child(("Polyline", "Clothoid", "ClothoidSpline", "Nurbs"))
        read = getattr(self, "_shape_" + shape.tag)
        traj = m.Trajectory(self.value(node, "name", tscope),
                            self.boolean(node, "closed", tscope), read(shape, tscope, timed))
        return traj, source

    def _shape_Polyline(self, poly, scope, timed):
        vertices = []
        for v in poly.findall("Vertex"):
            time = self.number(v, "time", scope, None)
            if timed:
                if time is None:
                    raise v.error("needs attribute time (the TimeReference is a Timing)")
                if vertices and time < vertices[-1].time:
                    raise v.error("time: %g comes before the previous vertex's %g"
                                  % (time, vertices[-1].time))
            vertices.append(m.Vertex(self.position(v.need("Position"), scope), time))
        if len(vertices) < 2:
            raise poly.error("needs at least 2 <Vertex>es, got %d" % len(vertices))
        return m.Polyline(tuple(vertices))

    def _shape_Clothoid(self, c, scope, timed):
        prime = self.number(c, "curvaturePrime", scope, None)
        if prime is None:
            prime = self.number(c, "curvatureDot", scope, None)
        if prime is None:
            raise c.error("needs attribute curvaturePrime (1.1) or curvatureDot (1.0)")
        return m.Clothoid(self.number(c, "curvature", scope), prime,
                          self.number(c, "length", scope, positive=True),
                          self.position(c.need("Position"), scope),
                          self.number(c, "startTime", scope, None),
                          self.number(c, "stopTime", scope, None))

    def _shape_ClothoidSpline(self, c, scope, timed):
        segments = []
        for i, s in enumerate(c.findall("ClothoidSplineSegment")):
            start = s.find("PositionStart")
            segments.append(m.ClothoidSplineSegment(
                self.number(s, "curvatureStart", scope), self.number(s, "curvatureEnd", scope),
                self.number(s, "length", scope, positive=True),
                self.number(s, "hOffset", scope, 0.0), self.number(s, "timeStart", scope, None),
                self.position(start, scope) if start is not None else None))
        if not segments:
            raise c.error("needs at least one <ClothoidSplineSegment>")
        return m.ClothoidSpline(tuple(segments), self.number(c, "timeEnd", scope, None))

    def _shape_Nurbs(self, n, scope, timed):
        order = self.value(n, "order", scope, "unsignedInt")
        points = tuple(m.ControlPoint(self.position(p.need("Position"), scope),
                                      self.number(p, "time", scope, None),
                                      self.number(p, "weight", scope, 1.0, positive=True))
                       for p in n.findall("ControlPoint"))
        knots = tuple(self.number(k, "value", scope) for k in n.findall("Knot"))
        if order < 1 or len(points) < order:
            raise n.error("order: %d needs at least as many <ControlPoint>s, got %d"
                          % (order, len(points)))
        if len(knots) != len(points) + order:
            raise n.error("needs %d <Knot>s (control points + order), got %d"
                          % (len(points) + order, len(knots)))
        if any(b < a for a, b in zip(knots, knots[1:])):
            raise n.error("the <Knot> values must not decrease")
        return m.Nurbs(order, points, knots)
