"""The storyboard's geometric entity conditions (docs/scenarios.md, "Conditions"): speed,
positions reached, distances, headway and time to collision (convoy_scenario.geometry).
Positions other than world and entity-relative ones are resolved by the player's
resolve_position (conditions.point). coordinateSystem lane is measured as road (s, t);
trajectory is not evaluated."""

import math

from . import conditions as cond
from . import geometry as g
from . import model as m


def geometric_value(board, c, test, name, env, compare):
    """The value of a SpeedCondition, ReachPosition, Distance, RelativeDistance,
    TimeHeadway or TimeToCollision condition for the triggering entity name."""
    a = env.body(name, c)
    need = lambda body, key: env.need(body, key, c)  # noqa: E731
    system = getattr(test, "coordinate_system", "entity")
    if system == "trajectory":
        raise env.error(c, "coordinateSystem trajectory is not evaluated")
    system = "road" if system == "lane" else system
    try:
        if isinstance(test, m.SpeedCondition):
            speed = a.speed
            if test.direction in ("longitudinal", "lateral"):
                speed = cond.direction(a.vx, a.vy, a.yaw, test.direction)
            elif test.direction == "vertical":
                speed = float(cond.state_key(env, c, name, "vz", 0.0))
            return compare(speed, test.rule, test.value)
        if isinstance(test, m.ReachPositionCondition):
            px, py = cond.point(board, test.position, c, env)
            return math.hypot(a.x - px, a.y - py) <= test.tolerance
        if isinstance(test, m.DistanceCondition):
            px, py = cond.point(board, test.position, c, env)
            if test.distance_type in ("euclidianDistance", "cartesianDistance"):
                d = g.point_euclidean(a, px, py, test.freespace)
            else:
                axis = 0 if test.distance_type == "longitudinal" else 1
                d = abs(g.point_axis_distance(a, px, py, axis, test.freespace))
            return compare(d, test.rule, test.value)
        if isinstance(test, m.TimeToCollisionCondition) and not isinstance(test.entity, str):
            px, py = cond.point(board, test.entity, c, env)
            b = g.Body("position", px, py, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
        else:
            b = env.body(test.entity, c)
        if isinstance(test, m.RelativeDistanceCondition):
            d = g.relative_distance(a, b, test.distance_type, test.freespace, system, need)
        elif isinstance(test, m.TimeHeadwayCondition):
            d = g.time_headway(a, b, test.freespace, system, need)
        else:
            d = g.time_to_collision(a, b, test.distance_type, test.freespace)
        return compare(d, test.rule, test.value)
    except ValueError as e:
        raise env.error(c, str(e)) from None
