"""The ego's route as the planner's path (issue 27: "its path follows the route (lane centre
ahead), not the current curvature").

A RoutePath is a polyline in the world frame with its arc length. `locate(x, y)` gives a point's
(s, d): s the arc length of its nearest point on the route, d its signed distance from it
(positive to the left of the route's direction), searched within an s window so that a route
passing the same place twice (a loop) is read at the right pass. `heading(s)` is the route's
direction there. Used by ego_planner.Planner; see docs/architecture.md, "Ego planner".
"""
import bisect
import csv
import math


class RoutePath:
    def __init__(self, points):
        pts = []
        for x, y in points:
            if not pts or math.hypot(x - pts[-1][0], y - pts[-1][1]) > 1e-6:
                pts.append((float(x), float(y)))
        if len(pts) < 2:
            raise ValueError("a route needs at least 2 distinct points, got %d" % len(pts))
        self.points = pts
        self.s = [0.0]
        for (x0, y0), (x1, y1) in zip(pts, pts[1:]):
            self.s.append(self.s[-1] + math.hypot(x1 - x0, y1 - y0))

    @property
    def length(self):
        return self.s[-1]

    @classmethod
    def from_csv(cls, path):
        """A route CSV with columns x, y (ego_route.csv, as make_config.py writes it)."""
        with open(path) as f:
            return cls([(float(r["x"]), float(r["y"])) for r in csv.DictReader(f)])

    def _segment(self, i, x, y):
        (x0, y0), (x1, y1) = self.points[i], self.points[i + 1]
        dx, dy = x1 - x0, y1 - y0
        seg = self.s[i + 1] - self.s[i]
        u = ((x - x0) * dx + (y - y0) * dy) / (seg * seg)
        u = min(max(u, 0.0), 1.0)
        px, py = x0 + u * dx, y0 + u * dy
        d = math.hypot(x - px, y - py)
        side = dx * (y - y0) - dy * (x - x0)
        return self.s[i] + u * seg, math.copysign(d, side) if d > 0 else 0.0

    def locate(self, x, y, s_min=None, s_max=None):
        """(s, d) of the nearest route point to (x, y) with s in [s_min, s_max]."""
        lo = 0 if s_min is None else max(bisect.bisect_right(self.s, s_min) - 1, 0)
        hi = len(self.points) - 2 if s_max is None else min(
            bisect.bisect_left(self.s, s_max), len(self.points) - 2)
        best = None
        for i in range(lo, max(hi, lo) + 1):
            s, d = self._segment(i, x, y)
            if best is None or abs(d) < abs(best[1]):
                best = (s, d)
        return best

    def heading(self, s):
        i = min(max(bisect.bisect_right(self.s, s) - 1, 0), len(self.points) - 2)
        (x0, y0), (x1, y1) = self.points[i], self.points[i + 1]
        return math.atan2(y1 - y0, x1 - x0)

    def point(self, s):
        """The route's (x, y) at arc length s (clamped to the route)."""
        s = min(max(s, 0.0), self.length)
        i = min(max(bisect.bisect_right(self.s, s) - 1, 0), len(self.points) - 2)
        (x0, y0), (x1, y1) = self.points[i], self.points[i + 1]
        u = (s - self.s[i]) / (self.s[i + 1] - self.s[i])
        return x0 + u * (x1 - x0), y0 + u * (y1 - y0)
