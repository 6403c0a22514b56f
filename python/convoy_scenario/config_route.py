"""The ego's route and lane lookups of the config generator (make_config.py; docs/scenarios.md,
"Running a scenario": the ego's route)."""

import math
import os

from .config_agents import pose_of
from .xmltree import ScenarioError


def lane_of(odr, x, y, yaw, what, types=("driving",)):
    loc = odr.locate(x, y, yaw, max_distance=5.0)
    if loc is None or loc["type"] not in types:
        raise ScenarioError("%s at (%.2f, %.2f) is not on a %s lane of %s" % (
            what, x, y, " or ".join(types), os.path.basename(odr.xodr)))
    return loc


def route_points(odr, spec, start, player):
    """Points of an AssignRouteAction from the ego's start through its waypoints."""
    pts, prev = [], start
    for w in spec.waypoints:
        x, y, yaw = pose_of(player, w.position)
        loc = lane_of(odr, x, y, yaw, "a route waypoint")
        if (loc["road"], loc["lane"]) == tuple(prev[:2]) and abs(loc["s"] - prev[2]) < 1.0:
            continue  # the start itself (a route's first waypoint usually is)
        try:
            r, to = lane_route(odr, player.roads, prev, (loc["road"], loc["lane"], loc["s"]))
        except ScenarioError:
            if pts:
                raise
            continue   # a waypoint behind where the ego starts on its route
        pts += r["points"] if not pts else r["points"][1:]
        prev = to
    return pts, prev


def lane_route(odr, roads, frm, to):
    """(route, end) from a lane position to a waypoint: to its lane, else (a route goes by
    roads, as esmini's) to another lane of its road at its s driven the same way."""
    try:
        return odr.route(frm, to), to
    except ScenarioError as first:
        forward = roads.lane_info(to[0], to[1], to[2])["forward"]
        for lane in sorted(roads.lanes_at(to[0], to[2]), key=lambda ln: abs(ln - to[1])):
            if lane == to[1] or lane == 0:
                continue
            info = roads.lane_info(to[0], lane, to[2])
            if info["type"] != "driving" or info["forward"] != forward:
                continue
            try:
                return odr.route(frm, (to[0], lane, to[2])), (to[0], lane, to[2])
            except ScenarioError:
                continue
        raise first


def polyline_length(points):
    return math.fsum(math.hypot(q[0] - p[0], q[1] - p[1]) for p, q in zip(points, points[1:]))


def cut(points, length):
    """The polyline's first `length` m."""
    out, acc = [points[0]], 0.0
    for p, q in zip(points, points[1:]):
        d = math.hypot(q[0] - p[0], q[1] - p[1])
        if acc + d >= length:
            u = (length - acc) / d if d > 0 else 0.0
            out.append([p[0] + u * (q[0] - p[0]), p[1] + u * (q[1] - p[1]), q[2]])
            return out
        out.append(q)
        acc += d
    return out


def surface_pose(odr, pose, start):
    """(z, pitch) of a car at `pose` on the road's surface: the height under it and the slope
    from there to 1 m ahead (0, 0 on a flat map)."""
    z = start.get("z", 0.0)
    ahead = odr.locate(pose[0] + math.cos(pose[2]), pose[1] + math.sin(pose[2]), pose[2])
    dz = (ahead or {}).get("z", z) - z
    return z, (0.0 if dz == 0 else -math.atan2(dz, 1.0))
