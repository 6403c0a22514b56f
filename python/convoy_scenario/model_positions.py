"""Positions of the scenario model (OpenSCENARIO 1.x ``<Position>``), kept symbolic: a
position relative to an entity, a road or a route is resolved at run time by whoever has the
road map and the world (the player); ``as_dict()`` gives the JSON-able form the commands
carry. Angles rad, lengths m."""

from dataclasses import dataclass
from typing import Optional, Tuple

Orientation = Tuple[str, float, float, float]   # (type relative|absolute, h, p, r)


def _with_orientation(out, orientation):
    if orientation is not None:
        out["orientation"] = dict(zip(("type", "h", "p", "r"), orientation))
    return out


@dataclass(frozen=True)
class WorldPosition:
    x: float
    y: float
    z: float = 0.0
    h: Optional[float] = None  # None: not given
    p: float = 0.0
    r: float = 0.0

    def as_dict(self):
        return {"type": "world", "x": self.x, "y": self.y, "z": self.z,
                "h": self.h, "p": self.p, "r": self.r}


@dataclass(frozen=True)
class LanePosition:
    road_id: str
    lane_id: str
    s: float
    offset: float = 0.0
    orientation: Optional[Orientation] = None

    def as_dict(self):
        return _with_orientation({"type": "lane", "road": self.road_id, "lane": self.lane_id,
                                  "s": self.s, "offset": self.offset}, self.orientation)


@dataclass(frozen=True)
class RoadPosition:
    road_id: str
    s: float
    t: float
    orientation: Optional[Orientation] = None

    def as_dict(self):
        return _with_orientation({"type": "road", "road": self.road_id, "s": self.s,
                                  "t": self.t}, self.orientation)


@dataclass(frozen=True)
class RelativeWorldPosition:
    entity: str
    dx: float
    dy: float
    dz: float = 0.0
    orientation: Optional[Orientation] = None

    def as_dict(self):
        return _with_orientation({"type": "relative_world", "entity": self.entity,
                                  "dx": self.dx, "dy": self.dy, "dz": self.dz}, self.orientation)


@dataclass(frozen=True)
class RelativeObjectPosition:
    """dx forward, dy left in the entity's frame."""
    entity: str
    dx: float
    dy: float
    dz: float = 0.0
    orientation: Optional[Orientation] = None

    def as_dict(self):
        return _with_orientation({"type": "relative_object", "entity": self.entity,
                                  "dx": self.dx, "dy": self.dy, "dz": self.dz}, self.orientation)


@dataclass(frozen=True)
class RelativeRoadPosition:
    entity: str
    ds: float
    dt: float
    orientation: Optional[Orientation] = None

    def as_dict(self):
        return _with_orientation({"type": "relative_road", "entity": self.entity,
                                  "ds": self.ds, "dt": self.dt}, self.orientation)


@dataclass(frozen=True)
class RelativeLanePosition:
    """d_lane lanes away from the entity's lane; ds along the road's reference line or
    ds_lane along the lane centre (exactly one is given); offset from the lane centre."""
    entity: str
    d_lane: int
    ds: Optional[float] = None
    ds_lane: Optional[float] = None
    offset: float = 0.0
    orientation: Optional[Orientation] = None

    def as_dict(self):
        return _with_orientation({"type": "relative_lane", "entity": self.entity,
                                  "d_lane": self.d_lane, "ds": self.ds, "ds_lane": self.ds_lane,
                                  "offset": self.offset}, self.orientation)


@dataclass(frozen=True)
class GeoPosition:
    latitude: float                           # rad (1.2 latitudeDeg is converted)
    longitude: float
    altitude: float = 0.0
    orientation: Optional[Orientation] = None

    def as_dict(self):
        return _with_orientation({"type": "geo", "latitude": self.latitude,
                                  "longitude": self.longitude, "altitude": self.altitude},
                                 self.orientation)


@dataclass(frozen=True)
class RoutePosition:
    """A point of a route: kind "entity" (where the entity is, projected on the route),
    "road" (path_s along the route, t from the reference line) or "lane" (path_s, lane_id,
    lane_offset)."""
    route: object                             # model.Route
    kind: str
    entity: Optional[str] = None
    path_s: float = 0.0
    t: float = 0.0
    lane_id: Optional[str] = None
    lane_offset: float = 0.0
    orientation: Optional[Orientation] = None

    def as_dict(self):
        return _with_orientation({"type": "route", "route": self.route.as_dict(),
                                  "kind": self.kind, "entity": self.entity,
                                  "path_s": self.path_s, "t": self.t, "lane": self.lane_id,
                                  "lane_offset": self.lane_offset}, self.orientation)


@dataclass(frozen=True)
class TrajectoryPosition:
    trajectory: object                        # model.Trajectory
    s: float
    t: float = 0.0
    orientation: Optional[Orientation] = None

    def as_dict(self):
        return _with_orientation({"type": "trajectory", "trajectory": self.trajectory.name,
                                  "s": self.s, "t": self.t}, self.orientation)


POSITION_TAGS = ("WorldPosition", "RelativeWorldPosition", "RelativeObjectPosition",
                 "RoadPosition", "RelativeRoadPosition", "LanePosition", "RelativeLanePosition",
                 "RoutePosition", "GeoPosition", "TrajectoryPosition")
