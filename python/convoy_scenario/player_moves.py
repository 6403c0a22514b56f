"""How the player's running actions move an entity over one step (docs/scenarios.md, "The
player"): the esmini-compatible reading of OpenSCENARIO's default controller.

A move is made when the storyboard starts an action on an entity the player drives, stepped
once per scenario step before the entity moves (so an action started at t already acts on
the step from t to t + dt, as in esmini), and dropped when the storyboard ends or stops the
action's run. `step(st, dt)` returns the domains it moved itself ("longitudinal" when it
moved the entity along its path; otherwise the player moves it by speed x dt)."""

import math

from . import model as m
from .actions import shape_value
from .player_state import angle_diff, wrap

SMALL = 1e-9
BIG_RATE = 1e10


def perf_limits(perf):
    """(max acceleration, max deceleration, max speed), unlimited without a Performance."""
    if perf is None:
        return BIG_RATE, BIG_RATE, 1e6
    return (perf.max_acceleration or BIG_RATE, perf.max_deceleration or BIG_RATE,
            perf.max_speed or 1e6)


def shape_peak_slope(shape, span, duration):
    """The largest |d value / d param| of a transition of `span` over `duration`."""
    if duration <= SMALL or shape == "step":
        return BIG_RATE
    k = {"linear": 1.0, "sinusoidal": math.pi / 2.0, "cubic": 1.5}.get(shape, 1.0)
    return k * abs(span) / duration


class SpeedMove:
    """A SpeedAction: the speed follows the transition's shape over its parameter (time;
    distance and rate converted to time at the start), slowed down uniformly when its peak
    acceleration exceeds the entity's Performance; after the transition the speed goes to the
    target within the Performance's limits."""

    def __init__(self, spec, st, states, perf):
        self.spec, self.perf = spec, perf
        self.acc_max, self.dec_max, self.v_max = perf_limits(perf)
        self.states = states
        d = spec.dynamics
        self.shape = d.shape
        self.v0 = st.speed
        v1 = self.target()
        if d.shape == "step":
            self.duration = 0.0
        elif d.dimension == "time":
            self.duration = max(0.0, d.value)
        elif d.dimension == "rate":
            self.duration = abs(v1 - self.v0) / abs(d.value) if d.value else 0.0
        else:
            self.duration = self._distance_time(d.value, self.v0, v1)
        limit = self.acc_max if v1 > self.v0 else self.dec_max
        peak = shape_peak_slope(self.shape, v1 - self.v0, self.duration)
        self.scale = peak / limit if self.duration > SMALL and peak > limit else 1.0
        self.param = 0.0
        self.done = False
        self.continuous = isinstance(spec.target, m.RelativeTargetSpeed) and spec.target.continuous

    @staticmethod
    def _distance_time(dist, v0, v1):
        if abs(v1 - v0) < SMALL:
            return 0.0
        if abs(v0) > SMALL and abs(v1) > SMALL and (v0 > 0) != (v1 > 0):
            d0 = dist * v0 * v0 / (v0 * v0 + v1 * v1)
            return 2.0 * d0 / abs(v0) + 2.0 * (dist - d0) / abs(v1)
        return 2.0 * dist / abs(v0 + v1) if abs(v0 + v1) > SMALL else 0.0

    def target(self):
        tgt = self.spec.target
        if isinstance(tgt, m.AbsoluteTargetSpeed):
            v = tgt.value
        else:
            ref = self.states[tgt.entity].speed
            v = ref + tgt.value if tgt.value_type == "delta" else ref * tgt.value
        return max(-self.v_max, min(self.v_max, v))

    def step(self, st, dt):
        v1 = self.target()
        if self.duration <= SMALL:
            new = v1
        elif self.param >= self.duration - SMALL:
            acc = (v1 - st.speed) / dt if dt > SMALL else 0.0
            new = st.speed + max(-self.dec_max, min(self.acc_max, acc)) * dt
        else:
            self.param = min(self.duration, self.param + dt / self.scale)
            new = self.v0 + (v1 - self.v0) * shape_value(self.shape, self.param / self.duration)
            acc = (new - st.speed) / dt if dt > SMALL else 0.0
            if acc > self.acc_max + SMALL or acc < -self.dec_max - SMALL:
                new = st.speed + max(-self.dec_max, min(self.acc_max, acc)) * dt
        if self.param >= self.duration - SMALL and abs(new - v1) < 1e-6:
            new = v1
            self.done = not self.continuous
        st.speed = max(-self.v_max, min(self.v_max, new))
        return ()


class LaneChangeMove:
    """A LaneChangeAction: the entity is re-anchored on the target lane at once, and its offset
    from that lane's centre goes from where it is to the target offset along the shape, over
    time (or rate) or over the distance travelled along the road. Each step it travels its
    speed x dt along its path: the lateral part from the shape's slope, the rest along the
    road; its heading follows the path."""

    def __init__(self, spec, st, states, movers, roads):
        self.spec, self.roads, self.movers = spec, roads, movers
        tgt = spec.target
        if isinstance(tgt, m.AbsoluteTargetLane):
            lane = int(tgt.lane)
        else:
            ref = states[tgt.entity]
            # value lanes to the reference's left: towards higher ids when it faces the road's s
            ref_forward = roads.lane_info(ref.road, ref.lane, ref.s)["forward"]
            h_road = ref.h_rel + (0.0 if ref_forward else math.pi)
            lane = ref.lane + tgt.value * (1 if math.cos(h_road) > 0 else -1)
            if lane == 0 or (lane > 0) != (ref.lane > 0):
                lane = (1 if lane > ref.lane else -1) * (abs(lane) + 1)
        self.target_lane = lane
        self.ok = st.road is not None
        if not self.ok:
            return
        sign = 1 if lane > 0 else -1
        faces_s = self._faces_plus_s(st)
        start = self._offset_on(st, lane)
        self.start = sign * start
        self.goal = sign * spec.target_lane_offset
        # aligned with the road, the way it was going (esmini: heading relative to road 0),
        # also onto a lane of the other direction
        fwd = self.roads.lane_info(st.road, st.lane, st.s)["forward"]
        self.base = 0.0 if fwd == faces_s else math.pi
        st.h_rel = self.base
        d = spec.dynamics
        span = self.goal - self.start
        if d.shape == "step":
            self.length = 0.0
        elif d.dimension == "rate":
            self.length = abs(span) / abs(d.value) if d.value else 0.0
        else:
            self.length = max(0.0, d.value)
        self.param = 0.0
        self.done = False

    def _faces_plus_s(self, st):
        fwd = self.roads.lane_info(st.road, st.lane, st.s)["forward"]
        return math.cos(st.h_rel + (0.0 if fwd else math.pi)) > 0

    def _offset_on(self, st, lane):
        """The entity's offset from the centre of `lane` (same road and s)."""
        here = self.roads.lane_info(st.road, st.lane, st.s)["centre_t"] + st.offset
        try:
            there = self.roads.lane_info(st.road, lane, st.s)["centre_t"]
        except Exception:  # noqa: BLE001 - no such lane here: stay on the current one
            self.target_lane = st.lane
            return st.offset
        st.lane, st.offset = lane, here - there
        return st.offset

    def step(self, st, dt):
        if not self.ok or self.done:
            return ()
        d = self.spec.dynamics
        step_len = abs(st.speed) * dt
        if step_len < SMALL:
            return ("longitudinal",)
        sign = 1 if st.lane > 0 else -1
        if self.length <= SMALL or d.shape == "step":
            offset, along = self.goal, step_len
            self.done = True
        elif d.dimension in ("time", "rate"):
            rate = self._slope() / self.length  # per second
            lat = dt * abs(rate)
            if lat < step_len:
                along = math.sqrt(step_len ** 2 - lat ** 2)
                self.param = min(self.length, self.param + dt)
                offset = self._value()
            else:
                along = 0.0
                self.param = min(self.length, self.param + step_len * self.length / abs(self.goal - self.start))
                offset = self.start + (self.goal - self.start) * self.param / self.length
        else:
            rate = self._slope() / self.length  # per metre
            along = math.sqrt(step_len ** 2 / (1.0 + rate ** 2))
            self.param = min(self.length, self.param + along)
            offset = self._value()
        x0, y0 = st.x, st.y
        st.offset = sign * offset
        self.roads_move(st, along)
        if self.param >= self.length - SMALL or abs(offset - self.goal) < SMALL:
            self.done = True
            st.h_rel = self.base
        elif along > SMALL and math.hypot(st.x - x0, st.y - y0) > SMALL:
            # the heading of the step's path (its lateral part from the shape); a step too
            # slow to go forward (lateral only) keeps the heading: a car does not turn sideways
            lane_h = self.roads.lane_pose(st.road, st.lane, st.s, st.offset)[3]
            path_h = math.atan2(st.y - y0, st.x - x0) + (math.pi if st.speed < 0 else 0.0)
            st.h_rel = angle_diff(path_h, lane_h)
        self.movers.update_pose(st)
        return ("longitudinal", "lateral")

    def roads_move(self, st, along):
        h_rel = st.h_rel
        self.movers.move_along(st, math.copysign(along, st.speed))
        st.h_rel = h_rel

    def _slope(self):
        tau = self.param / self.length
        shape = self.spec.dynamics.shape
        if shape == "linear":
            k = 1.0
        elif shape == "cubic":
            k = 6 * tau * (1 - tau)
        else:
            k = math.pi * math.sin(math.pi * tau) / 2.0
        return k * (self.goal - self.start)

    def _value(self):
        return self.start + (self.goal - self.start) * shape_value(self.spec.dynamics.shape,
                                                                   self.param / self.length)


class TrajectoryMove:
    """A FollowTrajectoryAction: its shape as points (player_shapes.py), resolved at the start.
    With a Timing (and times on the shape) the entity is where the trajectory is at the step's
    end time; without, it travels its speed x dt along it (from initialDistanceOffset). Its
    heading is the points' h interpolated when every point gives one, else the segment's
    direction."""

    def __init__(self, spec, st, t0, movers, points):
        self.spec, self.movers = spec, movers
        if len(points) == 1:
            points = points * 2
        self.pts = [(p[0], p[1], p[2] or 0.0) for p in points]
        self.hs = [p[3] for p in points]
        self.cum = [0.0]
        for p, q in zip(self.pts, self.pts[1:]):
            self.cum.append(self.cum[-1] + math.hypot(q[0] - p[0], q[1] - p[1]))
        times = [p[4] for p in points]
        self.timed = spec.timing is not None and all(x is not None for x in times)
        if self.timed:
            base = t0 if spec.timing.domain == "relative" else 0.0
            self.times = [base + spec.timing.scale * x + spec.timing.offset for x in times]
        self.dist = spec.initial_distance_offset or 0.0
        self.t = t0
        self.done = False

    def _at(self, i, u):
        j = min(i, len(self.pts) - 2)
        p, q = self.pts[j], self.pts[j + 1]
        pos = [p[k] + (q[k] - p[k]) * u for k in range(3)]
        if all(h is not None for h in self.hs):
            h = self.hs[j] + angle_diff(self.hs[j + 1], self.hs[j]) * u
        else:
            h = math.atan2(q[1] - p[1], q[0] - p[0])
        return pos, h

    def _by_distance(self, d):
        d = max(0.0, min(self.cum[-1], d))
        i = 0
        while i < len(self.cum) - 2 and self.cum[i + 1] < d:
            i += 1
        span = self.cum[i + 1] - self.cum[i]
        return self._at(i, 0.0 if span <= 0 else (d - self.cum[i]) / span)

    def _by_time(self, t):
        ts = self.times
        if t <= ts[0]:
            return self._at(0, 0.0), 0.0
        if t >= ts[-1]:
            return self._at(len(ts) - 2, 1.0), 0.0
        i = 0
        while i < len(ts) - 2 and ts[i + 1] <= t:
            i += 1
        span = ts[i + 1] - ts[i]
        u = 1.0 if span <= 0 else (t - ts[i]) / span
        seg = self.cum[i + 1] - self.cum[i]
        return self._at(i, u), (seg / span if span > 0 else 0.0)

    def step(self, st, dt):
        if self.done:
            return ()
        self.t += dt
        if self.timed:
            (pos, h), speed = self._by_time(self.t)
            st.speed = speed if self.t < self.times[-1] else st.speed
            self.done = self.t >= self.times[-1] - SMALL
        else:
            self.dist += abs(st.speed) * dt
            pos, h = self._by_distance(self.dist)
            self.done = self.dist >= self.cum[-1] - SMALL and not self.spec.closed
        self.movers.place_world(st, pos[0], pos[1], pos[2], wrap(h))
        return ("longitudinal", "lateral")
