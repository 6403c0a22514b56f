"""Running actions: what an action asks of its actor at time t, and when it has reached its
goal (docs/scenarios.md, "Actions"). The executor moves nobody: an ActionRun computes the
target where that is arithmetic and reports completion from the actor's state.

- SpeedAction: from the actor's speed v0 at the start to the target v1 (absolute, or the
  reference entity's speed + value / x value, read at the start, or every step when
  continuous). Shapes over tau = (t - t0) / T in [0, 1]: step (v1 at once), linear (tau),
  cubic (3 tau^2 - 2 tau^3), sinusoidal ((1 - cos(pi tau)) / 2). T: the time given; for a
  linear rate r, |v1 - v0| / |r|; for a linear distance d, 2 d / (v0 + v1). Target:
  {"speed", "target_speed", "acceleration"}. It ends when tau has reached 1 and the actor's
  speed is within SPEED_TOLERANCE of v1; a continuous one never ends by itself.
- LaneChangeAction: the target lane is absolute, or the reference entity's lane moved by
  value lanes to the left of the reference's direction of travel (right-hand traffic:
  towards higher ids on lanes with negative ids, lower ids on positive ones; lane 0 is
  skipped), read at the start. Progress = shape(tau), tau = elapsed time / the time given, or
  the actor's path length since the start / the distance given. Target: {"lane",
  "from_lane", "road", "offset", "progress"}. It ends when tau reaches 1.
- FollowTrajectoryAction with a Timing: vertex times map to simulation time as
  scale x time + offset (absolute) or t0 + scale x time + offset (relative); the target is the
  position interpolated linearly in time (clamped to the ends), its yaw (the vertices' h
  interpolated the short way when every vertex gives h, else the segment's direction) and
  the segment's speed. It ends at the last vertex's time. With TimeReference/None the times
  are ignored: the target is the polyline and its length, and it ends when the actor is
  within TRAJECTORY_END_TOLERANCE of the last vertex or past it along the last segment.
- AssignRouteAction, TeleportAction, EnvironmentAction end at once; their target is the route,
  the position, the weather keys.
- Control domains: SpeedAction longitudinal; LaneChangeAction and an untimed trajectory
  lateral; a timed trajectory both. A new run on an actor stops the actor's running runs of
  another action that share a domain.
"""

import math

from . import model as m
from .weather import environment_to_weather

SPEED_TOLERANCE = 0.1           # m/s
TRAJECTORY_END_TOLERANCE = 0.5  # m
TIME_EPS = 1e-9


def shape_value(shape, tau):
    tau = max(0.0, min(1.0, tau))
    if shape == "step":
        return 1.0
    if shape == "linear":
        return tau
    if shape == "cubic":
        return 3 * tau * tau - 2 * tau * tau * tau
    return (1.0 - math.cos(math.pi * tau)) / 2.0


def shape_slope(shape, tau):
    """d shape / d tau."""
    if shape == "step" or tau < 0 or tau >= 1:
        return 0.0
    if shape == "linear":
        return 1.0
    if shape == "cubic":
        return 6 * tau - 6 * tau * tau
    return math.pi * math.sin(math.pi * tau) / 2.0


def shift_lane(lane, value):
    """The lane value lanes to the left of a road user driving in lane (right-hand traffic,
    OpenDRIVE ids); lane 0 is skipped."""
    lane = int(lane)
    direction = 1 if lane < 0 else -1
    if value < 0:
        direction, value = -direction, -value
    for _ in range(value):
        lane += direction
        if lane == 0:
            lane += direction
    return str(lane)


class ActionRun:
    """One action applied to one actor (or a global action, actor None) from t0 on."""

    domains = frozenset()

    def __init__(self, name, spec, actor, t0, env, where=""):
        self.name, self.spec, self.actor, self.t0 = name, spec, actor, t0
        self.where = where
        self.active = True
        self.overridden = False
        self.start(env)

    def start(self, env):
        pass

    def update(self, t, env):
        """(target dict, done) at t."""
        raise NotImplementedError


class InstantRun(ActionRun):
    def update(self, t, env):
        s = self.spec
        if isinstance(s, m.TeleportAction):
            return {"position": s.position.as_dict()}, True
        if isinstance(s, m.AssignRouteAction):
            return {"route": s.name, "closed": s.closed,
                    "waypoints": [{"position": w.position.as_dict(),
                                   "route_strategy": w.route_strategy} for w in s.waypoints]}, True
        return {"environment": s.environment.name,
                "weather": environment_to_weather(s.environment)}, True


class SpeedRun(ActionRun):
    domains = frozenset(("longitudinal",))

    def _target(self, env):
        tgt = self.spec.target
        if isinstance(tgt, m.AbsoluteTargetSpeed):
            v = tgt.value
        else:
            ref = env.body(tgt.entity, self).speed
            v = ref + tgt.value if tgt.value_type == "delta" else ref * tgt.value
        return max(-self._max_speed(env), min(self._max_speed(env), v))

    def _max_speed(self, env):
        """The actor's Performance maxSpeed (the target is capped there, as in esmini)."""
        try:
            perf = env.scenario.entity(self.actor).object.performance
        except (AttributeError, KeyError):
            return float("inf")
        return perf.max_speed if perf is not None and perf.max_speed else float("inf")

    def start(self, env):
        self.v0 = env.body(self.actor, self).speed
        self.v1 = self._target(env)
        d = self.spec.dynamics
        if d.shape == "step":
            self.duration = 0.0
        elif d.dimension == "time":
            self.duration = d.value
        elif d.dimension == "rate":
            self.duration = abs(self.v1 - self.v0) / abs(d.value)
        else:
            if self.v0 + self.v1 <= 0:
                raise env.error(self, "a linear SpeedAction over a distance needs v0 + v1 > 0 "
                                      "(v0 %g, target %g)" % (self.v0, self.v1))
            self.duration = 2.0 * d.value / (self.v0 + self.v1)

    def update(self, t, env):
        tgt = self.spec.target
        continuous = isinstance(tgt, m.RelativeTargetSpeed) and tgt.continuous
        if continuous:
            self.v1 = self._target(env)
        shape = self.spec.dynamics.shape
        elapsed = t - self.t0
        tau = 1.0 if self.duration <= 0 else min(1.0, elapsed / self.duration)
        speed = self.v0 + (self.v1 - self.v0) * shape_value(shape, tau)
        accel = 0.0
        if self.duration > 0 and tau < 1.0:
            accel = (self.v1 - self.v0) * shape_slope(shape, tau) / self.duration
        reached = elapsed >= self.duration - TIME_EPS and \
            abs(env.body(self.actor, self).speed - self.v1) <= SPEED_TOLERANCE
        return ({"speed": speed, "target_speed": self.v1, "acceleration": accel},
                reached and not continuous)


class LaneChangeRun(ActionRun):
    domains = frozenset(("lateral",))

    def start(self, env):
        me = env.body(self.actor, self)
        tgt = self.spec.target
        if isinstance(tgt, m.AbsoluteTargetLane):
            self.lane = tgt.lane
            self.road = me.road
        else:
            ref = env.body(tgt.entity, self)
            self.lane = shift_lane(env.need(ref, "lane", self), tgt.value)
            self.road = ref.road
        self.from_lane = me.lane
        self.travelled = 0.0
        self.last = (me.x, me.y)

    def update(self, t, env):
        d = self.spec.dynamics
        me = env.body(self.actor, self)
        self.travelled += math.hypot(me.x - self.last[0], me.y - self.last[1])
        self.last = (me.x, me.y)
        if d.shape == "step":
            tau = 1.0
        elif d.dimension == "time":
            tau = (t - self.t0) / d.value
        else:
            tau = self.travelled / d.value
        done = tau >= 1.0 - TIME_EPS
        return ({"lane": self.lane, "from_lane": self.from_lane, "road": self.road,
                 "offset": self.spec.target_lane_offset,
                 "progress": shape_value(d.shape, tau)}, done)


class TrajectoryRun(ActionRun):
    def start(self, env):
        s = self.spec
        self.points = [(v.position.x, v.position.y, v.position.z) for v in s.vertices]
        self.length = sum(math.hypot(q[0] - p[0], q[1] - p[1])
                          for p, q in zip(self.points, self.points[1:]))
        if s.timing is not None:
            base = self.t0 if s.timing.domain == "relative" else 0.0
            self.times = [base + s.timing.scale * v.time + s.timing.offset for v in s.vertices]
            self.domains = frozenset(("longitudinal", "lateral"))
        else:
            self.times = None
            self.domains = frozenset(("lateral",))
            env.body(self.actor, self)

    def _segment_yaw(self, i):
        p, q = self.points[i], self.points[i + 1]
        return math.atan2(q[1] - p[1], q[0] - p[0])

    def update(self, t, env):
        if self.times is None:
            me = env.body(self.actor, self)
            end, prev = self.points[-1], self.points[-2]
            ex, ey = end[0] - prev[0], end[1] - prev[1]
            n = math.hypot(ex, ey)
            rx, ry = me.x - end[0], me.y - end[1]
            near = math.hypot(rx, ry) <= TRAJECTORY_END_TOLERANCE
            past = n > 0 and (rx * ex + ry * ey) / n >= 0 and \
                abs(rx * ey - ry * ex) / n <= TRAJECTORY_END_TOLERANCE
            return ({"vertices": [list(p) for p in self.points], "length": self.length},
                    near or past)
        ts, pts = self.times, self.points
        if t <= ts[0]:
            i, u = 0, 0.0
        elif t >= ts[-1]:
            i, u = len(pts) - 2, 1.0
        else:
            i = max(k for k in range(len(ts) - 1) if ts[k] <= t)
            while i < len(ts) - 2 and ts[i + 1] <= t:
                i += 1
            span = ts[i + 1] - ts[i]
            u = 1.0 if span <= 0 else (t - ts[i]) / span
        p, q = pts[i], pts[i + 1]
        pos = [p[k] + (q[k] - p[k]) * u for k in range(3)]
        hs = [v.position.h for v in self.spec.vertices]
        if all(h is not None for h in hs):
            dh = math.atan2(math.sin(hs[i + 1] - hs[i]), math.cos(hs[i + 1] - hs[i]))
            yaw = hs[i] + dh * u
        else:
            yaw = self._segment_yaw(i)
        span = ts[i + 1] - ts[i]
        moving = ts[0] <= t < ts[-1] and span > 0
        speed = math.hypot(q[0] - p[0], q[1] - p[1]) / span if moving else 0.0
        return ({"x": pos[0], "y": pos[1], "z": pos[2], "yaw": yaw, "speed": speed,
                 "vertices": [list(pt) for pt in pts], "length": self.length},
                t >= ts[-1] - TIME_EPS)


PLAYER_LONGITUDINAL = (m.LongitudinalDistanceAction, m.SynchronizeAction, m.SpeedProfileAction)
PLAYER_LATERAL = (m.LaneOffsetAction, m.LateralDistanceAction)


class MoveRun(ActionRun):
    """An action the player (player.py) carries out on an entity it moves: it runs until the
    player lists it in the actor's state as `finished`. On an entity the player does not move
    (a road-user engine's), it ends at once."""

    def start(self, env):
        spec = self.spec
        if isinstance(spec, PLAYER_LONGITUDINAL):
            self.domains = frozenset(("longitudinal",))
        elif isinstance(spec, PLAYER_LATERAL):
            self.domains = frozenset(("lateral",))
        else:
            timed = getattr(spec, "timing", None) is not None
            self.domains = frozenset(("longitudinal", "lateral") if timed else ("lateral",))

    def update(self, t, env):
        state = (getattr(env, "world", None) or {}).get(self.actor) or {}
        if "finished" not in state:
            return {}, True
        return {}, self.name in state["finished"]


def _played(env, actor):
    world = getattr(env, "world", None) or {}
    return actor is not None and "finished" in (world.get(actor) or {})


def make_run(name, spec, actor, t0, env, where=""):
    if isinstance(spec, m.SpeedAction):
        cls = SpeedRun
    elif isinstance(spec, m.LaneChangeAction):
        cls = LaneChangeRun
    elif isinstance(spec, PLAYER_LONGITUDINAL + PLAYER_LATERAL) or (
            isinstance(spec, m.FollowTrajectoryAction) and _played(env, actor)):
        cls = MoveRun
    elif isinstance(spec, m.FollowTrajectoryAction) and (
            not spec.vertices or spec.closed or
            not all(isinstance(v.position, m.WorldPosition) for v in spec.vertices)):
        cls = InstantRun   # issue 25: other shapes and positions wait for their run
    elif isinstance(spec, m.FollowTrajectoryAction):
        cls = TrajectoryRun
    else:
        cls = InstantRun
    return cls(name, spec, actor, t0, env, where)
