"""Positions of the scenario model resolved against the road map and the entities' current
states (docs/scenarios.md, "The player"): a dict with either road, lane, s, offset (and h_rel,
the heading relative to the lane's driving direction) or x, y, z, h (world)."""

import math

from . import model as m
from .player_state import angle_diff
from .xmltree import ScenarioError


def _orientation(o, lane_heading):
    """h_rel of an Orientation (type, h, p, r) on a lane whose driving direction is
    lane_heading; 0 without one."""
    if o is None:
        return 0.0
    kind, h = o[0], o[1] or 0.0
    return angle_diff(h, lane_heading) if kind == "absolute" else h


def resolve(position, states, roads, player=None):
    """The position as a dict (module doc); player (the Player) gives routes. position: a model
    position or its as_dict()."""
    if isinstance(position, dict):
        position = position_from_dict(position)
    if isinstance(position, m.WorldPosition):
        return {"x": position.x, "y": position.y, "z": position.z, "h": position.h}
    if isinstance(position, m.LanePosition):
        lane = int(position.lane_id)
        if lane == 0:   # the reference line: a road point (esmini accepts it)
            return _on_road(roads, position.road_id, position.s, position.offset,
                            position.orientation)
        heading = roads.lane_pose(position.road_id, lane, position.s, position.offset)[3]
        return {"road": str(position.road_id), "lane": lane, "s": position.s,
                "offset": position.offset,
                "h_rel": _orientation(position.orientation, heading)}
    resolver = _RESOLVERS.get(type(position).__name__)
    if resolver is None:
        raise ScenarioError("%s is not supported where the player places an entity" %
                            type(position).__name__)
    if resolver is _route:
        return _route(position, states, roads, player)
    return resolver(position, states, roads)


def _relative_world(p, states, roads):
    ref = states[p.entity]
    h = _relative_heading(p.orientation, ref.h)
    return {"x": ref.x + p.dx, "y": ref.y + p.dy, "z": ref.z + (p.dz or 0.0), "h": h}


def _relative_object(p, states, roads):
    ref = states[p.entity]
    c, s = math.cos(ref.h), math.sin(ref.h)
    h = _relative_heading(p.orientation, ref.h)
    return {"x": ref.x + c * p.dx - s * p.dy, "y": ref.y + s * p.dx + c * p.dy,
            "z": ref.z + (p.dz or 0.0), "h": h}


def _relative_heading(o, ref_h):
    """An orientation relative to an entity (esmini: relative unless given as absolute)."""
    if o is None:
        return ref_h
    return (o[1] or 0.0) if o[0] == "absolute" else ref_h + (o[1] or 0.0)


def relative_lane_id(lane, delta):
    """The lane delta lanes from lane by OpenDRIVE ids, skipping the centre lane 0."""
    out = lane + delta
    if lane != 0 and delta != 0 and (out == 0 or (out > 0) != (lane > 0)):
        out += 1 if delta > 0 else -1
    return out


def _lane_at_t(roads, road, s, t):
    """(lane, offset from its centre) of the lane containing road t at s (the nearest)."""
    best = None
    for lane in roads.lanes_at(road, s):
        if lane == 0:
            continue
        info = roads.lane_info(road, lane, s)
        d = abs(t - info["centre_t"])
        inside = d <= info["width"] / 2.0 + 1e-9
        key = (not inside, d)
        if best is None or key < best[0]:
            best = (key, lane, t - info["centre_t"], info["forward"])
    if best is None:
        raise ScenarioError("road %s has no lane at s=%g" % (road, s))
    return best[1], best[2], best[3]


def _on_road(roads, road, s, t, orientation):
    """A road point (road, s, t) as a lane position; heading relative to the road's reference
    direction unless absolute."""
    lane, offset, forward = _lane_at_t(roads, road, s, t)
    base = 0.0 if forward else math.pi       # the road's direction relative to the lane's
    if orientation is not None and orientation[0] == "absolute":
        lane_h = roads.lane_pose(road, lane, s, offset)[3]
        h_rel = angle_diff(orientation[1] or 0.0, lane_h)
    else:
        h_rel = base + (orientation[1] or 0.0 if orientation is not None else 0.0)
    return {"road": str(road), "lane": lane, "s": s, "offset": offset, "h_rel": h_rel}


def _road(p, states, roads):
    return _on_road(roads, p.road_id, p.s, p.t, p.orientation)


def _moved_ref(states, name, roads, distance, along_lane):
    """A copy of an entity's lane state moved `distance` m: along its lane's driving direction
    (along_lane; the way it faces) or along the road's s."""
    from .player_state import EntityState, LaneMover
    ref = states[name]
    if ref.road is None:
        raise ScenarioError("entity %r is not on a road: a position relative to its lane needs one" % name)
    tmp = EntityState(name, ref.length, ref.width, ref.length_offset)
    tmp.road, tmp.lane, tmp.s, tmp.offset, tmp.h_rel = ref.road, ref.lane, ref.s, ref.offset, ref.h_rel
    forward = roads.lane_info(ref.road, ref.lane, ref.s)["forward"]
    if not along_lane:
        tmp.h_rel = 0.0 if forward else math.pi   # face +s
    if distance:
        LaneMover(roads).move_along(tmp, distance)
    return tmp, forward


def _relative_road(p, states, roads):
    tmp, _ = _moved_ref(states, p.entity, roads, p.ds, False)
    t = roads.lane_info(tmp.road, tmp.lane, tmp.s)["centre_t"] + tmp.offset
    return _on_road(roads, tmp.road, tmp.s, t + p.dt, p.orientation)


def _relative_lane(p, states, roads):
    along_lane = p.ds is None
    ref = states[p.entity]
    tmp, _ = _moved_ref(states, p.entity, roads, p.ds_lane if along_lane else p.ds, along_lane)
    faces_lane = math.cos(ref.h_rel) >= 0
    if along_lane and not (faces_lane and ref.lane < 0):
        lane, offset = relative_lane_id(tmp.lane, -p.d_lane), -p.offset
    else:
        lane, offset = relative_lane_id(tmp.lane, p.d_lane), p.offset
    dh = p.orientation[1] or 0.0 if p.orientation is not None else 0.0
    if p.orientation is not None and p.orientation[0] == "absolute":
        h_rel = angle_diff(dh, roads.lane_pose(tmp.road, lane, tmp.s, offset)[3])
    elif along_lane:
        h_rel = dh
    else:
        forward = roads.lane_info(tmp.road, lane, tmp.s)["forward"]
        h_rel = dh + (0.0 if forward else math.pi)
    return {"road": tmp.road, "lane": lane, "s": tmp.s, "offset": offset, "h_rel": h_rel}


def _route(p, states, roads, player):
    path = player.route_path(p.route)
    if p.kind == "entity":
        ref = states[p.entity]
        path_s = path.project(ref.x, ref.y)
    else:
        path_s = p.path_s
    x, y, h = path.at(path_s)
    loc = roads.locate(x, y, heading=h, max_distance=2.0)
    if loc is None:
        return {"x": x, "y": y, "z": None, "h": h}
    road, s = str(loc["road"]), float(loc["s"])
    if p.kind == "lane":
        lane = int(p.lane_id)
        return {"road": road, "lane": lane, "s": s, "offset": p.lane_offset,
                "h_rel": _orientation(p.orientation, roads.lane_pose(road, lane, s)[3])}
    if p.kind == "road":
        return _on_road(roads, road, s, p.t, p.orientation)
    return {"road": road, "lane": int(loc["lane"]), "s": s, "offset": float(loc["t"]),
            "h_rel": _orientation(p.orientation, loc["heading"])}


_RESOLVERS = {
    "RoutePosition": _route,
    "RelativeWorldPosition": _relative_world,
    "RelativeObjectPosition": _relative_object,
    "RoadPosition": _road,
    "RelativeRoadPosition": _relative_road,
    "RelativeLanePosition": _relative_lane,
}


def _orient(d):
    o = d.get("orientation")
    return None if o is None else (o.get("type"), o.get("h"), o.get("p"), o.get("r"))


def position_from_dict(d):
    """The model position of a position's as_dict() (what the storyboard hands the resolver)."""
    kind = d.get("type")
    if kind == "world":
        return m.WorldPosition(d["x"], d["y"], d.get("z") or 0.0, d.get("h"), d.get("p") or 0.0,
                               d.get("r") or 0.0)
    if kind == "lane":
        return m.LanePosition(str(d["road"]), str(d["lane"]), d["s"], d.get("offset", 0.0), _orient(d))
    if kind == "road":
        return m.RoadPosition(str(d["road"]), d["s"], d["t"], _orient(d))
    if kind == "relative_world":
        return m.RelativeWorldPosition(d["entity"], d["dx"], d["dy"], d.get("dz", 0.0), _orient(d))
    if kind == "relative_object":
        return m.RelativeObjectPosition(d["entity"], d["dx"], d["dy"], d.get("dz", 0.0), _orient(d))
    if kind == "relative_road":
        return m.RelativeRoadPosition(d["entity"], d["ds"], d["dt"], _orient(d))
    if kind == "relative_lane":
        return m.RelativeLanePosition(d["entity"], d["d_lane"], d.get("ds"), d.get("ds_lane"),
                                      d.get("offset", 0.0), _orient(d))
    if kind == "route":
        r = d["route"]
        route = m.Route(r["name"], r["closed"], tuple(
            m.Waypoint(position_from_dict(w["position"]), w["route_strategy"]) for w in r["waypoints"]))
        return m.RoutePosition(route, d["kind"], d.get("entity"), d.get("path_s", 0.0), d.get("t", 0.0),
                               d.get("lane"), d.get("lane_offset", 0.0), _orient(d))
    raise ScenarioError("a %s position is not supported where the player places an entity" % kind)
