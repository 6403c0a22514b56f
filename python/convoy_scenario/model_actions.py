"""The actions of the scenario model beyond the first subset (model.py keeps SpeedAction,
LaneChangeAction, AssignRouteAction, FollowTrajectoryAction, TeleportAction,
EnvironmentAction): controllers, distance keeping, synchronisation, appearance, trailers,
parameters and variables, infrastructure and traffic, trajectory shapes. Frozen
dataclasses, SI units; positions are model_positions objects, kept symbolic."""

from dataclasses import dataclass
from typing import Optional, Tuple

# --- controllers ---------------------------------------------------------------------------


@dataclass(frozen=True)
class ActivateControllerAction:
    """None: the domain is left as it is."""
    lateral: Optional[bool] = None
    longitudinal: Optional[bool] = None
    lighting: Optional[bool] = None
    animation: Optional[bool] = None
    object_controller: Optional[str] = None   # 1.3 objectControllerRef


@dataclass(frozen=True)
class AssignControllerAction:
    controller: Optional[object]              # model.Controller (None: 1.3 ObjectController ref)
    object_controller: Optional[str] = None
    activate_lateral: Optional[bool] = None
    activate_longitudinal: Optional[bool] = None
    activate_lighting: Optional[bool] = None
    activate_animation: Optional[bool] = None


@dataclass(frozen=True)
class ControllerOverride:
    """One child of OverrideControllerValueAction: kind Throttle, Brake, Clutch,
    ParkingBrake, SteeringWheel or Gear; values (name, value) such as value, maxRate,
    maxTorque, number, gear."""
    kind: str
    active: bool
    values: Tuple[Tuple[str, object], ...] = ()


@dataclass(frozen=True)
class OverrideControllerValueAction:
    overrides: Tuple[ControllerOverride, ...]


@dataclass(frozen=True)
class ControllerAction:
    """A ControllerAction with several parts (OpenSCENARIO 1.0 has both an Assign and an
    Override); one part alone is read as that part's action."""
    actions: Tuple[object, ...]


# --- longitudinal and lateral --------------------------------------------------------------


@dataclass(frozen=True)
class DynamicConstraints:
    max_acceleration: Optional[float] = None
    max_deceleration: Optional[float] = None
    max_speed: Optional[float] = None
    max_acceleration_rate: Optional[float] = None
    max_deceleration_rate: Optional[float] = None


@dataclass(frozen=True)
class LongitudinalDistanceAction:
    entity: str
    distance: Optional[float]                 # exactly one of distance and time_gap
    time_gap: Optional[float]
    freespace: bool
    continuous: bool
    coordinate_system: str = "entity"         # entity, road, lane, trajectory
    displacement: str = "trailingReferencedEntity"   # or leadingReferencedEntity, any
    constraints: Optional[DynamicConstraints] = None


@dataclass(frozen=True)
class SpeedProfileEntry:
    speed: float
    time: Optional[float] = None              # duration of the entry (s), None: as fast as allowed


@dataclass(frozen=True)
class SpeedProfileAction:
    entries: Tuple[SpeedProfileEntry, ...]
    following_mode: str = "follow"            # position or follow
    entity: Optional[str] = None              # entityRef: speeds are relative to it
    constraints: Optional[DynamicConstraints] = None


@dataclass(frozen=True)
class LaneOffsetAction:
    shape: str                                # step, linear, cubic, sinusoidal
    max_lateral_acc: Optional[float]
    offset: float                             # m, positive to the left
    entity: Optional[str] = None              # RelativeTargetLaneOffset: from its offset
    continuous: bool = False


@dataclass(frozen=True)
class LateralDistanceAction:
    entity: str
    distance: Optional[float]
    freespace: bool
    continuous: bool
    coordinate_system: str = "entity"
    displacement: str = "any"                 # any, leftToReferencedEntity, rightToReferencedEntity
    constraints: Optional[DynamicConstraints] = None


@dataclass(frozen=True)
class FinalSpeed:
    """AbsoluteSpeed (value) or RelativeSpeedToMaster (value, value_type delta|factor);
    steady state: (kind distance|time, value) before the target position."""
    kind: str                                 # absolute or relative
    value: float
    value_type: Optional[str] = None
    steady_state: Optional[Tuple[str, float]] = None


@dataclass(frozen=True)
class SynchronizeAction:
    master: str
    master_position: object
    position: object
    final_speed: Optional[FinalSpeed] = None
    tolerance_master: Optional[float] = None  # 1.0 targetToleranceMaster
    tolerance: Optional[float] = None


# --- routing -------------------------------------------------------------------------------


@dataclass(frozen=True)
class AcquirePositionAction:
    position: object


@dataclass(frozen=True)
class Polyline:
    vertices: Tuple[object, ...]              # model.Vertex


@dataclass(frozen=True)
class Clothoid:
    curvature: float                          # 1/m at the start
    curvature_prime: float                    # 1/m^2 (1.0 curvatureDot)
    length: float
    position: object
    start_time: Optional[float] = None
    stop_time: Optional[float] = None


@dataclass(frozen=True)
class ClothoidSplineSegment:
    curvature_start: float
    curvature_end: float
    length: float
    h_offset: float = 0.0
    time_start: Optional[float] = None
    position_start: Optional[object] = None


@dataclass(frozen=True)
class ClothoidSpline:
    segments: Tuple[ClothoidSplineSegment, ...]
    time_end: Optional[float] = None


@dataclass(frozen=True)
class ControlPoint:
    position: object
    time: Optional[float] = None
    weight: float = 1.0


@dataclass(frozen=True)
class Nurbs:
    order: int
    control_points: Tuple[ControlPoint, ...]
    knots: Tuple[float, ...]


@dataclass(frozen=True)
class Trajectory:
    name: str
    closed: bool
    shape: object


# --- appearance, visibility, trailers ------------------------------------------------------


@dataclass(frozen=True)
class VisibilityAction:
    graphics: bool
    traffic: bool
    sensors: bool
    sensor_refs: Tuple[str, ...] = ()


@dataclass(frozen=True)
class LightStateAction:
    light_type: str                           # vehicleLightType or userDefinedLightType
    mode: str                                 # on, off, flashing
    transition_time: float = 0.0
    luminous_intensity: Optional[float] = None
    flashing_on: Optional[float] = None
    flashing_off: Optional[float] = None
    color: Optional[Tuple[str, Tuple[Tuple[str, float], ...]]] = None  # (colorType, (RGB/CMYK))
    user_defined: bool = False


@dataclass(frozen=True)
class AnimationAction:
    animation_type: str
    duration: Optional[float] = None
    loop: bool = False
    state: Optional[float] = None


@dataclass(frozen=True)
class ConnectTrailerAction:
    trailer: str


@dataclass(frozen=True)
class DisconnectTrailerAction:
    pass


# --- parameters, variables, infrastructure, traffic ----------------------------------------


@dataclass(frozen=True)
class ParameterAction:
    """ParameterAction / VariableAction: set (value, converted to the declared type) or
    modify by add / multiply (a number). The storyboard executes it."""
    name: str
    operation: str                            # set, add, multiply
    value: object
    variable: bool = False


@dataclass(frozen=True)
class TrafficSignalStateAction:
    name: str                                 # the signal's id
    state: str


@dataclass(frozen=True)
class TrafficSignalControllerAction:
    controller: str
    phase: str


@dataclass(frozen=True)
class TrafficSignalState:
    signal: str
    state: str


@dataclass(frozen=True)
class Phase:
    name: str
    duration: float
    states: Tuple[TrafficSignalState, ...] = ()


@dataclass(frozen=True)
class TrafficSignalController:
    name: str
    phases: Tuple[Phase, ...]
    delay: float = 0.0
    reference: Optional[str] = None


@dataclass(frozen=True)
class TrafficDefinition:
    name: str
    vehicle_categories: Tuple[Tuple[str, float], ...] = ()   # (category, weight)
    controllers: Tuple[Tuple[object, float], ...] = ()       # (Controller, weight)


@dataclass(frozen=True)
class TrafficSwarmAction:
    central_entity: str
    inner_radius: float
    semi_major_axis: float
    semi_minor_axis: float
    number_of_vehicles: int
    offset: float = 0.0
    velocity: Optional[float] = None
    definition: Optional[TrafficDefinition] = None


@dataclass(frozen=True)
class TrafficSourceAction:
    position: object
    radius: float
    rate: float
    velocity: Optional[float] = None
    definition: Optional[TrafficDefinition] = None


@dataclass(frozen=True)
class TrafficSinkAction:
    position: object
    radius: float
    rate: Optional[float] = None
    definition: Optional[TrafficDefinition] = None


@dataclass(frozen=True)
class TrafficStopAction:
    name: Optional[str] = None


# Actions that the storyboard executes itself (instantly) and those that move no one
STORYBOARD_ACTIONS = (ParameterAction, TrafficSignalStateAction, TrafficSignalControllerAction)
