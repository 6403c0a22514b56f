"""Plane geometry for the scores (docs/scoring.md): a route polyline (arc length, the nearest
point to a position) and oriented boxes (corners, overlap, a segment crossing a box).

Boxes follow Convoy's RoadUser convention: (x, y) is the reference point, the box's centre lies
`length_offset` ahead of it along `yaw`. Corners are in nuPlan's order: front-left, rear-left,
rear-right, front-right. Overlap is tested with separating axes; boxes that only touch
overlap (as shapely's `intersects`, which nuPlan uses)."""

import math

import numpy as np


def route_polyline(route):
    """The route's points as an (n, 2) array and their arc length along it (n,). `route` is
    {"points": [[x, y], ...] or [{"x", "y"}, ...]} or the list itself. Consecutive equal
    points are dropped. ValueError for fewer than two distinct points."""
    pts = route.get("points") if isinstance(route, dict) else route
    if pts is None:
        raise ValueError("route: no 'points'")
    try:
        arr = np.array([(float(p["x"]), float(p["y"])) if isinstance(p, dict)
                        else (float(p[0]), float(p[1])) for p in pts], float).reshape(-1, 2)
    except (KeyError, TypeError, ValueError, IndexError) as e:
        raise ValueError("route: bad point (%s)" % e) from None
    if not np.all(np.isfinite(arr)):
        raise ValueError("route: a point is not finite")
    if len(arr) > 1:
        keep = np.concatenate([[True], np.any(np.diff(arr, axis=0) != 0.0, axis=1)])
        arr = arr[keep]
    if len(arr) < 2:
        raise ValueError("route: fewer than two distinct points")
    seg = np.hypot(*np.diff(arr, axis=0).T)
    return arr, np.concatenate([[0.0], np.cumsum(seg)])


def project_on_polyline(pts, cum, x, y, s_lo=-math.inf, s_hi=math.inf):
    """The point of the polyline nearest to (x, y), among the segments that overlap the arc
    length interval [s_lo, s_hi]: (arc length s, distance, heading of its segment). Ties go to
    the first segment."""
    j0 = max(0, int(np.searchsorted(cum, s_lo, side="right")) - 1)
    j1 = min(len(pts) - 1, int(np.searchsorted(cum, s_hi, side="left")) + 1)
    if j1 <= j0:
        j0, j1 = max(0, j1 - 1), max(1, j1)
    a = pts[j0:j1]
    d = pts[j0 + 1:j1 + 1] - a
    L2 = np.einsum("ij,ij->i", d, d)
    u = np.clip(((x - a[:, 0]) * d[:, 0] + (y - a[:, 1]) * d[:, 1]) / L2, 0.0, 1.0)
    px = a[:, 0] + u * d[:, 0]
    py = a[:, 1] + u * d[:, 1]
    dist = np.hypot(x - px, y - py)
    k = int(np.argmin(dist))
    s = float(cum[j0 + k] + u[k] * math.sqrt(L2[k]))
    return s, float(dist[k]), math.atan2(d[k, 1], d[k, 0])


def box_corners(x, y, yaw, length, width, length_offset=0.0):
    """Corners (..., 4, 2) of boxes (arrays broadcast): front-left, rear-left, rear-right,
    front-right."""
    x, y, yaw, length, width, length_offset = np.broadcast_arrays(
        *(np.asarray(v, float) for v in (x, y, yaw, length, width, length_offset)))
    c, s = np.cos(yaw), np.sin(yaw)
    cx, cy = x + length_offset * c, y + length_offset * s
    hl, hw = 0.5 * length, 0.5 * width
    lon = np.stack([hl, -hl, -hl, hl], axis=-1)
    lat = np.stack([hw, hw, -hw, -hw], axis=-1)
    px = cx[..., None] + lon * c[..., None] - lat * s[..., None]
    py = cy[..., None] + lon * s[..., None] + lat * c[..., None]
    return np.stack([px, py], axis=-1)


def _separated(a, b, axes):
    """True where the projections of point sets a (..., m, 2) and b (..., n, 2) on one of the
    axes (..., k, 2) do not meet."""
    pa = np.einsum("...mj,...kj->...km", a, axes)
    pb = np.einsum("...nj,...kj->...kn", b, axes)
    gap = (pa.max(axis=-1) < pb.min(axis=-1)) | (pb.max(axis=-1) < pa.min(axis=-1))
    return gap.any(axis=-1)


def _edge_axes(corners):
    """The two edge directions of boxes (..., 4, 2): the normals of the other two edges."""
    return np.stack([corners[..., 0, :] - corners[..., 1, :],
                     corners[..., 1, :] - corners[..., 2, :]], axis=-2)


def boxes_overlap(a, b):
    """Whether boxes a and b (corner arrays (..., 4, 2), broadcast) overlap or touch."""
    a, b = np.broadcast_arrays(np.asarray(a, float), np.asarray(b, float))
    axes = np.concatenate([_edge_axes(a), _edge_axes(b)], axis=-2)
    return ~_separated(a, b, axes)


def segment_hits_box(p, q, corners):
    """Whether the segment p-q meets the box (corners (4, 2))."""
    seg = np.array([p, q], float)
    d = seg[1] - seg[0]
    axes = np.concatenate([_edge_axes(np.asarray(corners, float)), [[-d[1], d[0]]]])
    if d[0] == 0.0 and d[1] == 0.0:
        axes = axes[:2]
    return not bool(_separated(seg, np.asarray(corners, float), axes))


def relative_angle(x, y, yaw, ox, oy):
    """Angle (0..pi) between the heading `yaw` at (x, y) and the direction to (ox, oy); 0 when
    the points coincide (nuPlan's get_agent_relative_angle)."""
    dx, dy = ox - x, oy - y
    n = math.hypot(dx, dy)
    if n == 0.0:
        return 0.0
    c = (math.cos(yaw) * dx + math.sin(yaw) * dy) / n
    return math.acos(max(-1.0, min(1.0, c)))
