"""The scenario as read from an .xosc file: plain, immutable Python objects (frozen
dataclasses). Parameters are already resolved; positions, speeds and distances are SI
(m, m/s, rad, s) as in OpenSCENARIO. Every storyboard element and condition keeps the file
and line it came from (``where``)."""

from dataclasses import dataclass, field
from typing import Optional, Tuple


# --- positions (model_positions) and the new actions and conditions (model_actions,
# model_conditions) are part of this module's namespace -----------------------------------

from .model_positions import *  # noqa: F401,F403,E402
from .model_actions import *  # noqa: F401,F403,E402
from .model_conditions import *  # noqa: F401,F403,E402



# --- entities ------------------------------------------------------------------------------

@dataclass(frozen=True)
class BoundingBox:
    center: Tuple[float, float, float]       # from the entity's reference point
    length: float
    width: float
    height: float


@dataclass(frozen=True)
class Performance:
    max_speed: float
    max_acceleration: float
    max_deceleration: float


@dataclass(frozen=True)
class Vehicle:
    name: str
    category: str                             # OpenSCENARIO vehicleCategory: car, truck, ...
    bounding_box: BoundingBox
    performance: Performance
    axles: Tuple[Tuple[str, Tuple[Tuple[str, float], ...]], ...] = ()
    properties: Tuple[Tuple[str, str], ...] = ()
    model3d: Optional[str] = None
    mass: Optional[float] = None
    role: Optional[str] = None                # 1.2: none, ambulance, police, ...
    trailer_hitch: Optional[float] = None     # dx of the hitch from the reference point
    trailer_coupler: Optional[float] = None   # dx of the coupler (a trailer)
    trailer: Optional[object] = None          # Trailer: what is hitched at the start


@dataclass(frozen=True)
class Trailer:
    """A Vehicle's Trailer: an entity by name (TrailerRef) or a vehicle of its own (read as
    an entity named as the Vehicle, hitched to this one)."""
    entity: Optional[str] = None
    vehicle: Optional[Vehicle] = None


@dataclass(frozen=True)
class MiscObject:
    name: str
    category: str                             # obstacle, pole, tree, barrier, ...
    mass: float
    bounding_box: BoundingBox
    properties: Tuple[Tuple[str, str], ...] = ()
    model3d: Optional[str] = None


@dataclass(frozen=True)
class Controller:
    """A controller (ObjectController, ControllerCatalog entry or AssignControllerAction):
    its name, controllerType (1.2) and Properties; what it means is the player's."""
    name: str
    controller_type: Optional[str] = None     # movement, lateral, longitudinal, lighting, ...
    properties: Tuple[Tuple[str, str], ...] = ()
    catalog: Optional[object] = None          # CatalogSource


@dataclass(frozen=True)
class Pedestrian:
    name: str
    model: str
    mass: float
    category: str                             # pedestrian, wheelchair, animal
    bounding_box: BoundingBox
    properties: Tuple[Tuple[str, str], ...] = ()
    model3d: Optional[str] = None


@dataclass(frozen=True)
class CatalogSource:
    """Where a catalog entry came from: the catalog, the entry, the file and the values of
    its parameters after the reference's assignments."""
    catalog: str
    entry: str
    path: str
    parameters: Tuple[Tuple[str, object], ...] = ()


@dataclass(frozen=True)
class Entity:
    name: str
    kind: str                                 # "vehicle", "pedestrian" or "misc"
    object: object                            # Vehicle, Pedestrian or MiscObject
    catalog: Optional[CatalogSource] = None
    controllers: Tuple[Tuple[str, Controller], ...] = ()  # ObjectControllers (name, controller)


# --- environment ---------------------------------------------------------------------------

@dataclass(frozen=True)
class Sun:
    azimuth: float                            # rad, 0 north, pi/2 east
    elevation: float                          # rad above the horizon
    illuminance: Optional[float] = None       # lux


@dataclass(frozen=True)
class Precipitation:
    type: str                                 # dry, rain, snow
    intensity: Optional[float] = None         # 1.0: 0..1
    intensity_mm_h: Optional[float] = None    # 1.1+: precipitationIntensity, mm/h


@dataclass(frozen=True)
class Weather:
    sun: Optional[Sun] = None
    fog_visual_range: Optional[float] = None  # m
    precipitation: Optional[Precipitation] = None
    wind: Optional[Tuple[float, float]] = None  # (direction rad, speed m/s)
    cloud_state: Optional[str] = None
    temperature: Optional[float] = None
    atmospheric_pressure: Optional[float] = None


@dataclass(frozen=True)
class Environment:
    name: str
    time_of_day: Optional[Tuple[bool, str]] = None  # (animation, dateTime)
    weather: Optional[Weather] = None
    friction_scale_factor: Optional[float] = None


# --- actions -------------------------------------------------------------------------------

@dataclass(frozen=True)
class Dynamics:
    shape: str                                # step, linear, cubic, sinusoidal
    dimension: str                            # time, rate, distance
    value: float


@dataclass(frozen=True)
class AbsoluteTargetSpeed:
    value: float


@dataclass(frozen=True)
class RelativeTargetSpeed:
    entity: str
    value: float
    value_type: str                           # delta or factor
    continuous: bool


@dataclass(frozen=True)
class SpeedAction:
    dynamics: Dynamics
    target: object                            # AbsoluteTargetSpeed or RelativeTargetSpeed


@dataclass(frozen=True)
class AbsoluteTargetLane:
    lane: str


@dataclass(frozen=True)
class RelativeTargetLane:
    entity: str
    value: int


@dataclass(frozen=True)
class LaneChangeAction:
    dynamics: Dynamics
    target: object                            # AbsoluteTargetLane or RelativeTargetLane
    target_lane_offset: float = 0.0


@dataclass(frozen=True)
class Waypoint:
    position: object
    route_strategy: str


@dataclass(frozen=True)
class Route:
    name: str
    closed: bool
    waypoints: Tuple[Waypoint, ...]
    catalog: Optional[CatalogSource] = None

    def as_dict(self):
        return {"name": self.name, "closed": self.closed,
                "waypoints": [{"position": w.position.as_dict(),
                               "route_strategy": w.route_strategy} for w in self.waypoints]}


@dataclass(frozen=True)
class AssignRouteAction:
    name: str
    closed: bool
    waypoints: Tuple[Waypoint, ...]
    catalog: Optional[CatalogSource] = None   # the Route came from a RouteCatalog


@dataclass(frozen=True)
class Vertex:
    position: object                          # any position (WorldPosition in most files)
    time: Optional[float] = None


@dataclass(frozen=True)
class Timing:
    domain: str                               # absolute or relative
    scale: float
    offset: float


@dataclass(frozen=True)
class FollowTrajectoryAction:
    name: str
    vertices: Tuple[Vertex, ...]              # a Polyline's; () for the other shapes
    timing: Optional[Timing]                  # None: TimeReference/None (times ignored)
    following_mode: str = "follow"            # position or follow
    shape: object = None                      # Polyline, Clothoid, ClothoidSpline or Nurbs
    closed: bool = False
    initial_distance_offset: float = 0.0      # 1.2
    catalog: Optional[CatalogSource] = None   # the Trajectory came from a TrajectoryCatalog


@dataclass(frozen=True)
class TeleportAction:
    position: object


@dataclass(frozen=True)
class EnvironmentAction:
    environment: Environment


# --- conditions ----------------------------------------------------------------------------

@dataclass(frozen=True)
class SimulationTimeCondition:
    value: float
    rule: str


@dataclass(frozen=True)
class StoryboardElementStateCondition:
    element_type: str
    element_ref: str
    state: str
    element_path: str = ""                    # the element referred to, resolved at load


@dataclass(frozen=True)
class RelativeDistanceCondition:
    entity: str
    value: float
    freespace: bool
    distance_type: str                        # longitudinal, lateral, cartesianDistance, euclidianDistance
    rule: str
    coordinate_system: str = "entity"         # entity, road, lane (as road), trajectory
    along_route: bool = False                 # 1.0 alongRoute (read as coordinateSystem road)


@dataclass(frozen=True)
class TimeHeadwayCondition:
    entity: str
    value: float
    freespace: bool
    rule: str
    coordinate_system: str = "entity"
    along_route: bool = False


@dataclass(frozen=True)
class TimeToCollisionCondition:
    entity: object                            # an entity's name, or a position
    value: float
    freespace: bool
    rule: str
    distance_type: str = "euclidianDistance"
    coordinate_system: str = "entity"
    along_route: bool = False


@dataclass(frozen=True)
class ReachPositionCondition:
    position: object                          # any position (model_positions)
    tolerance: float


@dataclass(frozen=True)
class DistanceCondition:
    position: object
    value: float
    freespace: bool
    rule: str
    distance_type: str = "euclidianDistance"
    coordinate_system: str = "entity"
    along_route: bool = False


@dataclass(frozen=True)
class SpeedCondition:
    value: float
    rule: str
    direction: Optional[str] = None           # 1.2: longitudinal, lateral, vertical


@dataclass(frozen=True)
class Condition:
    name: str
    delay: float
    edge: str                                 # rising, falling, risingOrFalling, none
    test: object                              # one of the condition classes above
    triggering: Tuple[str, ...] = ()          # entity conditions: the triggering entities
    triggering_rule: str = "any"              # any or all
    where: str = ""


@dataclass(frozen=True)
class Trigger:
    groups: Tuple[Tuple[Condition, ...], ...]  # OR of groups, AND within a group


# --- storyboard ----------------------------------------------------------------------------

@dataclass(frozen=True)
class Action:
    name: str
    path: str                                 # Story::Act::Group::Maneuver::Event::Action
    spec: object                              # one of the action classes above
    private: bool                             # a PrivateAction (applies to the actors)
    where: str = ""


@dataclass(frozen=True)
class Event:
    name: str
    path: str
    priority: str                             # overwrite (override), skip, parallel
    maximum_execution_count: int
    actions: Tuple[Action, ...]
    start_trigger: Optional[Trigger]
    where: str = ""


@dataclass(frozen=True)
class Maneuver:
    name: str
    path: str
    events: Tuple[Event, ...]
    where: str = ""


@dataclass(frozen=True)
class ManeuverGroup:
    name: str
    path: str
    maximum_execution_count: int
    actors: Tuple[str, ...]
    maneuvers: Tuple[Maneuver, ...]
    where: str = ""
    select_triggering_entities: bool = False  # actors += the Act's triggering entities


@dataclass(frozen=True)
class Act:
    name: str
    path: str
    groups: Tuple[ManeuverGroup, ...]
    start_trigger: Optional[Trigger]
    stop_trigger: Optional[Trigger]
    where: str = ""


@dataclass(frozen=True)
class Story:
    name: str
    path: str
    acts: Tuple[Act, ...]
    where: str = ""


@dataclass(frozen=True)
class InitAction:
    entity: Optional[str]                     # None for a GlobalAction
    spec: object
    where: str = ""


@dataclass(frozen=True)
class FileHeader:
    rev_major: int
    rev_minor: int
    date: str
    description: str
    author: str
    license: Optional[Tuple[str, str, str, str]] = None  # (name, resource, spdxId, text)
    properties: Tuple[Tuple[str, str], ...] = ()


@dataclass(frozen=True)
class Scenario:
    path: str
    header: FileHeader
    parameters: Tuple[Tuple[str, object], ...]  # global parameters, resolved
    logic_file: Optional[str]                 # the .xodr, absolute
    scene_graph_file: Optional[str]
    entities: Tuple[Entity, ...]
    init: Tuple[InitAction, ...]
    stories: Tuple[Story, ...]
    stop_trigger: Optional[Trigger]
    catalog_dirs: Tuple[Tuple[str, str], ...] = field(default=())
    variables: Tuple[Tuple[str, str, object], ...] = ()  # (name, type, initial value)
    traffic_signal_controllers: Tuple[TrafficSignalController, ...] = ()
    parameter_types: Tuple[Tuple[str, str], ...] = ()    # global parameters' types

    def entity(self, name):
        for e in self.entities:
            if e.name == name:
                return e
        raise KeyError(name)
