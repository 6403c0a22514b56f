"""Geometry of the entity conditions: distances, time headway and time to collision between
entities given by their state (docs/scenarios.md, "Conditions").

A Body is an entity at one step: its reference point (x, y), heading yaw, velocity, and its
bounding box (length x width, its centre `length_offset` ahead of the reference point and
`lateral_offset` to its left). Distances with freespace=False are between reference points;
with freespace=True between the boxes (0 when they touch or overlap).
"""

import math
from dataclasses import dataclass
from typing import Optional

INF = math.inf


@dataclass(frozen=True)
class Body:
    name: str
    x: float
    y: float
    yaw: float
    speed: float
    vx: float
    vy: float
    length: float
    width: float
    length_offset: float = 0.0
    lateral_offset: float = 0.0
    road: Optional[str] = None
    lane: Optional[str] = None
    s: Optional[float] = None
    t: Optional[float] = None

    def to_local(self, px, py):
        """(px, py) in this body's frame: x forward, y left, from the reference point."""
        dx, dy = px - self.x, py - self.y
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        return dx * c + dy * s, -dx * s + dy * c

    def corners(self):
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        cx = self.x + self.length_offset * c - self.lateral_offset * s
        cy = self.y + self.length_offset * s + self.lateral_offset * c
        hl, hw = self.length / 2.0, self.width / 2.0
        return [(cx + a * c - b * s, cy + a * s + b * c)
                for a, b in ((hl, hw), (-hl, hw), (-hl, -hw), (hl, -hw))]

    def interval(self, axis):
        """The box's extent along its own x (axis 0) or y (axis 1), from the reference point."""
        if axis == 0:
            return self.length_offset - self.length / 2.0, self.length_offset + self.length / 2.0
        return self.lateral_offset - self.width / 2.0, self.lateral_offset + self.width / 2.0


def _gap(lo_a, hi_a, lo_b, hi_b):
    """Signed gap between intervals: > 0 when b is after a, < 0 when before, 0 if they
    overlap."""
    if lo_b > hi_a:
        return lo_b - hi_a
    if hi_b < lo_a:
        return hi_b - lo_a
    return 0.0


def signed_axis_distance(a, b, axis, freespace):
    """b's distance from a along a's x (axis 0, positive ahead) or y (axis 1, positive to
    the left)."""
    if not freespace:
        return a.to_local(b.x, b.y)[axis]
    coords = [a.to_local(px, py)[axis] for px, py in b.corners()]
    lo, hi = a.interval(axis)
    return _gap(lo, hi, min(coords), max(coords))


def point_axis_distance(a, px, py, axis, freespace):
    d = a.to_local(px, py)[axis]
    if not freespace:
        return d
    lo, hi = a.interval(axis)
    return _gap(lo, hi, d, d)


def _segment_point(p, q, r):
    """Distance from point r to segment pq."""
    dx, dy = q[0] - p[0], q[1] - p[1]
    n = dx * dx + dy * dy
    u = 0.0 if n == 0 else max(0.0, min(1.0, ((r[0] - p[0]) * dx + (r[1] - p[1]) * dy) / n))
    return math.hypot(p[0] + u * dx - r[0], p[1] + u * dy - r[1])


def _separated(pa, pb):
    """True when a separating axis (an edge normal of either convex polygon) exists."""
    for poly in (pa, pb):
        for i in range(len(poly)):
            p, q = poly[i], poly[(i + 1) % len(poly)]
            nx, ny = q[1] - p[1], p[0] - q[0]
            da = [nx * x + ny * y for x, y in pa]
            db = [nx * x + ny * y for x, y in pb]
            if max(da) < min(db) or max(db) < min(da):
                return True
    return False


def polygon_distance(pa, pb):
    """Distance between two convex polygons (0 when they touch or overlap)."""
    if not _separated(pa, pb):
        return 0.0
    best = INF
    for poly, other in ((pa, pb), (pb, pa)):
        for i in range(len(poly)):
            p, q = poly[i], poly[(i + 1) % len(poly)]
            for r in other:
                best = min(best, _segment_point(p, q, r))
    return best


def euclidean(a, b, freespace):
    if not freespace:
        return math.hypot(b.x - a.x, b.y - a.y)
    return polygon_distance(a.corners(), b.corners())


def point_euclidean(a, px, py, freespace):
    if not freespace:
        return math.hypot(px - a.x, py - a.y)
    return polygon_distance(a.corners(), [(px, py)])


def road_delta(a, b, axis, freespace, need):
    """Signed distance in road coordinates: s (axis 0) or t (axis 1) of b minus a's, along
    a's direction of travel (against s when a's lane id is positive); freespace subtracts
    half of both lengths (widths). need(body, key) raises when the state lacks a key."""
    key = "s" if axis == 0 else "t"
    va, vb = need(a, key), need(b, key)
    if a.road is not None and b.road is not None and a.road != b.road:
        raise ValueError("%s is on road %s and %s on road %s: road coordinates need one road"
                         % (a.name, a.road, b.name, b.road))
    d = vb - va
    if a.lane is not None and int(a.lane) > 0:
        d = -d
    if freespace:
        half = (a.length + b.length) / 2.0 if axis == 0 else (a.width + b.width) / 2.0
        d = math.copysign(max(0.0, abs(d) - half), d) if abs(d) > half else 0.0
    return d


def relative_distance(a, b, dtype, freespace, system, need):
    """RelativeDistanceCondition's distance (non-negative)."""
    if dtype in ("euclidianDistance", "cartesianDistance"):
        return euclidean(a, b, freespace)
    axis = 0 if dtype == "longitudinal" else 1
    if system == "road":
        return abs(road_delta(a, b, axis, freespace, need))
    return abs(signed_axis_distance(a, b, axis, freespace))


def time_headway(a, b, freespace, system, need):
    """Time for a to cover its longitudinal distance to b at a's speed; negative when b is
    behind a; +-inf when a is not moving forward (0 when the boxes overlap)."""
    if system == "road":
        d = road_delta(a, b, 0, freespace, need)
    else:
        d = signed_axis_distance(a, b, 0, freespace)
    if d == 0:
        return 0.0
    if a.speed <= 0:
        return math.copysign(INF, d)
    return d / a.speed


def time_to_collision(a, b, dtype, freespace):
    """Distance over closing speed (inf when not closing; 0 when touching and closing).
    Euclidean: the closing speed along the line between the reference points; longitudinal
    / lateral: along a's x / y axis."""
    wx, wy = b.vx - a.vx, b.vy - a.vy
    if dtype in ("euclidianDistance", "cartesianDistance"):
        px, py = b.x - a.x, b.y - a.y
        n = math.hypot(px, py)
        if n == 0:
            return 0.0
        closing = -(px * wx + py * wy) / n
        d = euclidean(a, b, freespace)
    else:
        axis = 0 if dtype == "longitudinal" else 1
        signed = signed_axis_distance(a, b, axis, freespace)
        raw = a.to_local(b.x, b.y)[axis]
        c, s = math.cos(a.yaw), math.sin(a.yaw)
        w_axis = wx * c + wy * s if axis == 0 else -wx * s + wy * c
        direction = 1.0 if raw >= 0 else -1.0
        closing = -direction * w_axis
        d = abs(signed)
    if closing <= 0:
        return INF
    return d / closing
