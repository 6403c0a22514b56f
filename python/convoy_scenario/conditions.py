"""Evaluating the conditions added with issue 25 for the storyboard (storyboard.py), from
the world-state keys the player fills (docs/scenarios.md): ax ay (world-frame
acceleration), odometer, collisions, offroad, end_of_road, road lane s, and the storyboard's
own parameters, variables and traffic signal states.

- TraveledDistance: odometer >= value. Acceleration: the world-frame (ax, ay) projected on
  the entity's heading (longitudinal) or its left (lateral); vertical: az (0 if absent);
  no direction: the magnitude of (ax, ay) with the sign of its longitudinal part (esmini:
  braking is negative). RelativeSpeed: the triggering entity's speed
  minus the reference's (esmini), or with a direction the triggering entity's velocity
  projected on the reference's axis minus the reference's own speed along it.
- EndOfRoad, Offroad, StandStill: true once the state (end_of_road, offroad, speed below
  STANDSTILL_SPEED, esmini's threshold) has held for at least duration, counted from the first step it held.
- Collision: the entity's collisions list names the EntityRef, or an entity of the ByType
  object type (vehicle, pedestrian, miscellaneous).
- RelativeClearance: true when no other entity (or none of the EntityRefs) is on the
  triggering entity's road, in a lane of the ranges (lane ids relative to its lane, counted
  to the left of the road's reference direction as esmini does, lane 0 skipped; no range:
  its own lane) and within distanceBackward behind and distanceForward ahead along its
  direction of travel (s); freespace subtracts half of both lengths; lanes of the other
  driving direction only with oppositeLanes; and (esmini) a driving lane with an id in the
  range exists there (ids as numbers, of the same direction unless oppositeLanes), when the
  storyboard has the map (`Storyboard.driving_lanes`, the player's).
- Parameter, Variable: the storyboard's current value against value by rule (numbers with
  EQUAL_TOLERANCE; text and booleans equal / not equal). TrafficSignal: the signal's state,
  set by TrafficSignalStateActions or by its controller's phase (false while neither gave
  one); TrafficSignalController: the controller's current phase.
"""

import math

from . import model as m

STANDSTILL_SPEED = 1e-3   # m/s
DURATION_EPS = 1e-9


def state_key(env, c, name, key, default=None):
    state = env.world.get(name)
    if state is None:
        raise env.error(c, "the world has no state for entity %r" % name)
    if state.get(key) is None:
        if default is not None:
            return default
        raise env.error(c, "entity %r's state has no %r" % (name, key))
    return state[key]


def _held(board, c, name, holds, duration, t):
    """True once holds has been true for duration (per condition and entity)."""
    key = (id(c), name)
    if not holds:
        board.since.pop(key, None)
        return False
    since = board.since.setdefault(key, t)
    return t - since >= duration - DURATION_EPS


def direction(vx, vy, yaw, direction):
    if direction == "longitudinal":
        return vx * math.cos(yaw) + vy * math.sin(yaw)
    return -vx * math.sin(yaw) + vy * math.cos(yaw)


def entity_value(board, c, test, name, env, compare):
    """The value of an issue-25 entity condition for the triggering entity name."""
    t = env.t
    if isinstance(test, m.TraveledDistanceCondition):
        return float(state_key(env, c, name, "odometer")) >= test.value - 1e-6
    if isinstance(test, m.EndOfRoadCondition):
        return _held(board, c, name, bool(state_key(env, c, name, "end_of_road")),
                     test.duration, t)
    if isinstance(test, m.OffroadCondition):
        return _held(board, c, name, bool(state_key(env, c, name, "offroad")), test.duration, t)
    if isinstance(test, m.StandStillCondition):
        a = env.body(name, c)
        return _held(board, c, name, abs(a.speed) < STANDSTILL_SPEED, test.duration, t)
    if isinstance(test, m.CollisionCondition):
        touched = state_key(env, c, name, "collisions")
        if test.entity is not None:
            return test.entity in touched
        kinds = {"vehicle": "vehicle", "pedestrian": "pedestrian", "miscellaneous": "misc"}
        want = kinds.get(test.object_type)
        for other in touched:
            try:
                if board.scenario.entity(other).kind == want:
                    return True
            except KeyError:
                if test.object_type == "external":
                    return True
        return False
    if isinstance(test, m.AccelerationCondition):
        a = env.body(name, c)
        ax = float(state_key(env, c, name, "ax"))
        ay = float(state_key(env, c, name, "ay"))
        if test.direction is None:   # esmini: the magnitude, signed as the longitudinal part
            lon = direction(ax, ay, a.yaw, "longitudinal")
            value = math.copysign(math.hypot(ax, ay), -1.0 if lon < 0 else 1.0)
        elif test.direction == "vertical":
            value = float(state_key(env, c, name, "az", 0.0))
        else:
            value = direction(ax, ay, a.yaw, test.direction)
        return compare(value, test.rule, test.value)
    if isinstance(test, m.RelativeSpeedCondition):
        a, b = env.body(name, c), env.body(test.entity, c)
        if test.direction is None:
            value = a.speed - b.speed
        elif test.direction == "vertical":
            value = float(state_key(env, c, name, "vz", 0.0)) - \
                float(state_key(env, c, test.entity, "vz", 0.0))
        else:
            value = direction(a.vx, a.vy, b.yaw, test.direction) - \
                direction(b.vx, b.vy, b.yaw, test.direction)
        return compare(value, test.rule, test.value)
    if isinstance(test, m.RelativeClearanceCondition):
        return _clear(board, c, test, name, env)
    raise env.error(c, "%s is not evaluated" % type(test).__name__)


def lanes_left(own, other):
    """How many lanes other is to the left of own, left of the road's reference direction
    (OpenDRIVE ids increase to the left; lane 0 skipped), as esmini counts dLaneId."""
    own, other = int(own), int(other)
    pos = lambda lane: lane if lane > 0 else lane + 1  # noqa: E731  (ids without the 0)
    return pos(other) - pos(own)


def _clear(board, c, test, name, env):
    a = env.body(name, c)
    road, lane, s = (env.need(a, k, c) for k in ("road", "lane", "s"))
    forward = 1.0 if int(lane) < 0 else -1.0
    ranges = test.lane_ranges or ((0, 0),)
    others = test.entities or tuple(e.name for e in board.scenario.entities)
    for other in others:
        if other == name or other not in env.world:
            continue
        b = env.body(other, c)
        if b.road is None or b.lane is None or b.s is None or str(b.road) != str(road):
            continue
        if not test.opposite_lanes and (int(b.lane) < 0) != (int(lane) < 0):
            continue
        dl = lanes_left(lane, b.lane)
        if not any(lo <= dl <= hi for lo, hi in ranges):
            continue
        ds = (b.s - s) * forward
        if test.freespace:
            half = (a.length + b.length) / 2.0
            ds = 0.0 if abs(ds) <= half else ds - math.copysign(half, ds)
        if -test.distance_backward <= ds <= test.distance_forward:
            return False
    return _lanes_exist(board, test, road, int(lane), float(s), ranges)


def _lanes_exist(board, test, road, lane, s, ranges):
    """esmini's second test: a driving lane with an id in lane + from .. lane + to (ids as
    numbers) exists at s, of the same direction unless oppositeLanes. Without the map
    (board.driving_lanes None) it is not checked."""
    lanes_at = getattr(board, "driving_lanes", None)
    if lanes_at is None:
        return True
    for other in lanes_at(str(road), s):
        if not test.opposite_lanes and (other < 0) != (lane < 0):
            continue
        if any(lane + lo <= other <= lane + hi for lo, hi in ranges):
            return True
    return False


def value_condition(board, test, t, env, c, compare):
    """ParameterCondition / VariableCondition / TrafficSignal(Controller)Condition /
    TimeOfDayCondition at time t."""
    if isinstance(test, m.ParameterCondition):
        store = board.variables if test.variable else board.parameters
        current = store[test.name]
        if isinstance(test.value, (int, float)) and not isinstance(test.value, bool):
            return compare(float(current), test.rule, float(test.value))
        equal = current == test.value
        return equal if test.rule == "equalTo" else not equal
    if isinstance(test, m.TrafficSignalCondition):
        return board.signal_state(test.name, t) == test.state   # unknown: false
    if isinstance(test, m.TrafficSignalControllerCondition):
        return board.controller_phase(test.controller, t) == test.phase
    raise env.error(c, "%s is not evaluated (no clock of day in the world)"
                    % type(test).__name__)


# --- the storyboard's own state: positions, traffic signals, parameters ----------------

def signal_state(board, signal, t):
    """A traffic signal's state: the last TrafficSignalStateAction's, else its
    controller's current phase's; None if neither gives one."""
    if signal in board.signals:
        return board.signals[signal]
    for ctrl in board.scenario.traffic_signal_controllers:
        phase = controller_phase(board, ctrl.name, t)
        for p in ctrl.phases:
            if p.name == phase:
                for s in p.states:
                    if s.signal == signal:
                        return s.state
    return None


def controller_phase(board, name, t):
    """The phase a TrafficSignalController is in at t: its phases cycle from its delay
    (or from the last TrafficSignalControllerAction, which starts the phase it names);
    None before the delay or without phases."""
    ctrl = next(c for c in board.scenario.traffic_signal_controllers if c.name == name)
    start, first = board.controller_start[name]
    total = sum(p.duration for p in ctrl.phases)
    if not ctrl.phases or t < start or total <= 0:
        return None
    into = (t - start) % total
    i = first
    while True:
        p = ctrl.phases[i % len(ctrl.phases)]
        if into < p.duration:
            return p.name
        into -= p.duration
        i += 1


def point(board, position, c, env):
    """(x, y) of a position in a condition."""
    if isinstance(position, m.WorldPosition):
        return position.x, position.y
    if isinstance(position, (m.RelativeWorldPosition, m.RelativeObjectPosition)):
        ref = env.body(position.entity, c)
        if isinstance(position, m.RelativeWorldPosition):
            return ref.x + position.dx, ref.y + position.dy
        cy, sy = math.cos(ref.yaw), math.sin(ref.yaw)
        return (ref.x + position.dx * cy - position.dy * sy,
                ref.y + position.dx * sy + position.dy * cy)
    if board.resolve_position is None:
        raise env.error(c, "a %s needs the road map (the player resolves it)"
                        % type(position).__name__)
    x, y = board.resolve_position(position.as_dict(), env.world)[:2]
    return float(x), float(y)


def execute(board, spec, t):
    """The storyboard's own instant actions: parameters, variables, traffic signals."""
    if isinstance(spec, m.ParameterAction):
        store = board.variables if spec.variable else board.parameters
        if spec.operation == "set":
            store[spec.name] = spec.value
        else:
            old = store[spec.name]
            new = old + spec.value if spec.operation == "add" else old * spec.value
            store[spec.name] = type(old)(new) if isinstance(old, int) and \
                float(new).is_integer() else new
    elif isinstance(spec, m.TrafficSignalStateAction):
        board.signals[spec.name] = spec.state
    elif isinstance(spec, m.TrafficSignalControllerAction):
        ctrl = next(c for c in board.scenario.traffic_signal_controllers
                    if c.name == spec.controller)
        index = [p.name for p in ctrl.phases].index(spec.phase)
        board.controller_start[spec.controller] = (t, index)
        for s in ctrl.phases[index].states:
            board.signals.pop(s.signal, None)
