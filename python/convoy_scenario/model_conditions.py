"""The conditions of the scenario model beyond the first subset (model.py keeps
SimulationTime, StoryboardElementState, RelativeDistance, TimeHeadway, TimeToCollision,
ReachPosition, Distance and Speed). Frozen dataclasses; convoy_scenario.conditions
evaluates them."""

from dataclasses import dataclass
from typing import Optional, Tuple


@dataclass(frozen=True)
class TraveledDistanceCondition:
    value: float


@dataclass(frozen=True)
class EndOfRoadCondition:
    duration: float


@dataclass(frozen=True)
class OffroadCondition:
    duration: float


@dataclass(frozen=True)
class StandStillCondition:
    duration: float


@dataclass(frozen=True)
class CollisionCondition:
    entity: Optional[str] = None              # EntityRef, or
    object_type: Optional[str] = None         # ByType: pedestrian, vehicle, miscellaneous


@dataclass(frozen=True)
class AccelerationCondition:
    value: float
    rule: str
    direction: Optional[str] = None           # longitudinal, lateral, vertical; None: magnitude


@dataclass(frozen=True)
class RelativeSpeedCondition:
    entity: str
    value: float
    rule: str
    direction: Optional[str] = None


@dataclass(frozen=True)
class RelativeClearanceCondition:
    distance_forward: float
    distance_backward: float
    freespace: bool
    opposite_lanes: bool
    lane_ranges: Tuple[Tuple[int, int], ...] = ()  # (from, to); () : the own lane only
    entities: Tuple[str, ...] = ()                 # () : every entity


@dataclass(frozen=True)
class ParameterCondition:
    name: str
    value: object                             # converted to the parameter's type
    rule: str
    variable: bool = False                    # a VariableCondition


@dataclass(frozen=True)
class TrafficSignalCondition:
    name: str
    state: str


@dataclass(frozen=True)
class TrafficSignalControllerCondition:
    controller: str
    phase: str


@dataclass(frozen=True)
class TimeOfDayCondition:
    date_time: str
    rule: str
