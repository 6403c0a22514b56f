"""Routes for the player (docs/scenarios.md, "The player"): a Route's waypoints joined by the
map's shortest lane routes, as a polyline with the roads and lanes it uses. An entity with a
route takes, at a fork, the lane on its route (else a lane of a road on it); RoutePositions are
points along it (pathS from the first waypoint)."""

import math

SAMPLE_DS = 1.0   # m between the route's points


class RoutePath:
    def __init__(self, roads, lane_points):
        """lane_points: [(road, lane, s), ...] of the waypoints, in order."""
        self.roads = roads
        self.points = []          # [x, y, heading]
        for a, b in zip(lane_points, lane_points[1:]):
            try:
                pts = roads.route(a, b, SAMPLE_DS)["points"]
            except Exception:  # noqa: BLE001 - no lane route between them: a straight join
                pts = [list(roads.lane_pose(a[0], a[1], a[2])[:2]) + [0.0],
                       list(roads.lane_pose(b[0], b[1], b[2])[:2]) + [0.0]]
            self.points.extend(pts if not self.points else pts[1:])
        if not self.points and lane_points:
            x, y, _, h, _ = roads.lane_pose(*lane_points[0])
            self.points = [[x, y, h]]
        self.cum = [0.0]
        for p, q in zip(self.points, self.points[1:]):
            self.cum.append(self.cum[-1] + math.hypot(q[0] - p[0], q[1] - p[1]))
        self.lanes, self.road_ids = set(), set()
        for road, lane, _ in lane_points:
            self.lanes.add((str(road), int(lane)))
            self.road_ids.add(str(road))
        for x, y, h in self.points[::2]:
            loc = roads.locate(x, y, heading=h, max_distance=1.0)
            if loc is not None:
                self.lanes.add((str(loc["road"]), int(loc["lane"])))
                self.road_ids.add(str(loc["road"]))

    @property
    def length(self):
        return self.cum[-1]

    def at(self, path_s):
        """(x, y, heading) at path_s m along the route (clamped to its ends)."""
        d = max(0.0, min(self.length, path_s))
        i = 0
        while i < len(self.cum) - 2 and self.cum[i + 1] < d:
            i += 1
        if len(self.points) == 1:
            return tuple(self.points[0])
        p, q = self.points[i], self.points[i + 1]
        span = self.cum[i + 1] - self.cum[i]
        u = 0.0 if span <= 0 else (d - self.cum[i]) / span
        return p[0] + (q[0] - p[0]) * u, p[1] + (q[1] - p[1]) * u, math.atan2(q[1] - p[1], q[0] - p[0])

    def project(self, x, y):
        """path_s of the route's point nearest to (x, y)."""
        best = (float("inf"), 0.0)
        for i, (p, q) in enumerate(zip(self.points, self.points[1:])):
            dx, dy = q[0] - p[0], q[1] - p[1]
            n2 = dx * dx + dy * dy
            u = 0.0 if n2 == 0 else max(0.0, min(1.0, ((x - p[0]) * dx + (y - p[1]) * dy) / n2))
            d = math.hypot(p[0] + u * dx - x, p[1] + u * dy - y)
            if d < best[0]:
                best = (d, self.cum[i] + u * math.sqrt(n2))
        return best[1]

    def prefers(self, road, lane):
        """0 for a lane on the route, 1 for another lane of a road on it, 2 otherwise."""
        if (str(road), int(lane)) in self.lanes:
            return 0
        return 1 if str(road) in self.road_ids else 2
