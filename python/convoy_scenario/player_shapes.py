"""A trajectory's shape as points for the player (docs/scenarios.md, "The player"): a Polyline's
vertices, a Clothoid or a ClothoidSpline integrated every SAMPLE_DS m, a Nurbs curve evaluated
(rational B-spline, de Boor) at SAMPLES_PER_SPAN points per knot span. Positions are resolved
when the action starts (relative ones against the entities then).

`shape_points(spec, place, entity_pose)` -> [(x, y, z, h or None, time or None)], where
place(position) -> (x, y, z, h or None) resolves a model position and entity_pose is the
actor's (x, y, z, h) for shapes that start where it is."""

import math

from . import model as m

SAMPLE_DS = 0.5
SAMPLES_PER_SPAN = 20


def shape_points(spec, place, entity_pose):
    shape = spec.shape
    if shape is None or isinstance(shape, m.Polyline):
        out = []
        for v in spec.vertices:
            x, y, z, h = place(v.position)
            out.append((x, y, z, h, v.time))
        return out
    if isinstance(shape, m.Clothoid):
        start = place(shape.position) if shape.position is not None else entity_pose
        pts = _clothoid(start, shape.curvature, shape.curvature_prime, shape.length)
        return _timed(pts, shape.start_time, shape.stop_time)
    if isinstance(shape, m.ClothoidSpline):
        return _clothoid_spline(shape, place, entity_pose)
    if isinstance(shape, m.Nurbs):
        return _nurbs(shape, place)
    raise ValueError("trajectory shape %s" % type(shape).__name__)


def _clothoid(start, k0, dk, length):
    """Points (x, y, z, h) every SAMPLE_DS m along a clothoid from start (x, y, z, h)."""
    x, y, z, h = start[0], start[1], start[2] or 0.0, start[3] or 0.0
    n = max(1, int(math.ceil(abs(length) / SAMPLE_DS)))
    ds = length / n
    pts = [(x, y, z, h)]
    for i in range(n):
        s0 = i * ds
        # midpoint rule on the heading over the sub-step
        hm = h + (k0 * (ds / 2) + dk * (s0 * ds / 2 + ds * ds / 8))
        x += ds * math.cos(hm)
        y += ds * math.sin(hm)
        h += k0 * ds + dk * (s0 * ds + ds * ds / 2)
        pts.append((x, y, z, h))
    return pts


def _timed(pts, t0, t1):
    """Times along the points by distance between t0 and t1 (None without both)."""
    if t0 is None or t1 is None:
        return [p + (None,) for p in pts]
    cum = [0.0]
    for p, q in zip(pts, pts[1:]):
        cum.append(cum[-1] + math.hypot(q[0] - p[0], q[1] - p[1]))
    total = cum[-1] or 1.0
    return [p + (t0 + (t1 - t0) * c / total,) for p, c in zip(pts, cum)]


def _clothoid_spline(shape, place, entity_pose):
    out = []
    pose = None
    segs = shape.segments
    for i, seg in enumerate(segs):
        if seg.position_start is not None:
            pose = place(seg.position_start)
        elif pose is None:
            pose = entity_pose
        start = (pose[0], pose[1], pose[2], (pose[3] or 0.0) + seg.h_offset)
        dk = (seg.curvature_end - seg.curvature_start) / seg.length if seg.length else 0.0
        pts = _clothoid(start, seg.curvature_start, dk, seg.length)
        t_end = segs[i + 1].time_start if i + 1 < len(segs) else shape.time_end
        timed = _timed(pts, seg.time_start, t_end)
        out.extend(timed if not out else timed[1:])
        pose = pts[-1]
    return out


def _basis(knots, p, u, i):
    """B-spline basis N_{i,p}(u) (Cox-de Boor)."""
    if p == 0:
        last = u >= knots[-1] and knots[i] < knots[i + 1] == knots[-1]
        return 1.0 if knots[i] <= u < knots[i + 1] or last else 0.0
    a = b = 0.0
    if knots[i + p] != knots[i]:
        a = (u - knots[i]) / (knots[i + p] - knots[i]) * _basis(knots, p - 1, u, i)
    if knots[i + p + 1] != knots[i + 1]:
        b = (knots[i + p + 1] - u) / (knots[i + p + 1] - knots[i + 1]) * _basis(knots, p - 1, u, i + 1)
    return a + b


def _nurbs(shape, place):
    p = shape.order - 1
    cps = [(place(c.position), c.weight, c.time) for c in shape.control_points]
    knots = list(shape.knots)
    lo, hi = knots[p], knots[len(cps)]
    spans = max(1, len(cps) - p)
    n = spans * SAMPLES_PER_SPAN
    timed = all(c[2] is not None for c in cps)
    out = []
    for k in range(n + 1):
        u = lo + (hi - lo) * k / n
        ws = [_basis(knots, p, u, i) * w for i, (_, w, _) in enumerate(cps)]
        total = sum(ws) or 1.0
        x = sum(wi * c[0][0] for wi, c in zip(ws, cps)) / total
        y = sum(wi * c[0][1] for wi, c in zip(ws, cps)) / total
        z = sum(wi * (c[0][2] or 0.0) for wi, c in zip(ws, cps)) / total
        t = sum(wi * c[2] for wi, c in zip(ws, cps)) / total if timed else None
        out.append((x, y, z, None, t))
    return out
