"""The player's moves that act relative to other entities or over a profile (docs/scenarios.md,
"The player"), read from the standard and, where it is vague, as esmini plays them:

- LaneOffsetAction: the offset from the lane centre goes to the target along the shape, over
  the time its peak lateral acceleration allows (maxLateralAcc); the entity travels along its
  lane as usual, heading along its path.
- LongitudinalDistanceAction: without limits the entity is put at the distance (or time gap)
  behind or ahead of the reference and takes its speed; with DynamicConstraints a critically
  damped spring on the distance error (stiffness 0.4 x the acceleration limit), its
  acceleration and jerk limited.
- LateralDistanceAction: the same across: the offset that gives the lateral distance, at once
  or through the spring.
- SynchronizeAction: each step the speed that brings the entity to its target position when
  the master reaches its own, linear to the final speed when one is given; ends when the
  master gets there.
- SpeedProfileAction: the speeds of its entries, one after the other, linear over each
  entry's time (as fast as the limits allow without one)."""

import math

from . import geometry as g
from . import model as m
from .actions import shape_value

BIG = 1e10
SPRING = 0.4
REACHED_M = 0.1          # LongitudinalDistance: within this of the requested distance
SYNC_TOLERANCE_M = 1.0   # Synchronize: the master has reached its position


def _limits(c):
    c = c or m.DynamicConstraints()
    return (c.max_acceleration or BIG, c.max_deceleration or BIG, c.max_speed or BIG,
            c.max_acceleration_rate or BIG, c.max_deceleration_rate or BIG)


def body(st):
    return g.Body(st.name, st.x, st.y, st.h, st.speed, st.vx, st.vy, st.length, st.width,
                  st.length_offset, 0.0, st.road, None if st.road is None else str(st.lane),
                  st.s if st.road is not None else None, st.road_t if st.road is not None else None)


def shape_duration(shape, span, acc):
    """The duration of an offset change of `span` whose peak second derivative is acc."""
    if shape == "step" or abs(span) < 1e-12 or not acc:
        return 0.0
    if shape == "sinusoidal":
        return math.pi * math.sqrt(abs(span) / (2.0 * acc))
    return math.sqrt(6.0 * abs(span) / acc)


class LaneOffsetMove:
    def __init__(self, spec, st, states, roads):
        self.spec, self.roads = spec, roads
        self.ok = st.road is not None
        if not self.ok:
            return
        self.start = st.offset
        if spec.entity is None:
            self.goal = spec.offset
        else:
            ref = states[spec.entity]
            ref_fwd = roads.lane_info(ref.road, ref.lane, ref.s)["forward"]
            faces_s = math.cos(ref.h_rel + (0.0 if ref_fwd else math.pi)) > 0
            t_goal = ref.road_t + spec.offset * (1 if faces_s else -1)
            self.goal = t_goal - roads.lane_info(st.road, st.lane, st.s)["centre_t"]
        self.duration = shape_duration(spec.shape, self.goal - self.start, spec.max_lateral_acc or 0.5)
        self.base = 0.0 if math.cos(st.h_rel) >= 0 else math.pi
        self.elapsed = 0.0
        self.done = False

    def step(self, st, dt):
        if not self.ok:
            return ()
        tau = 1.0 if self.duration <= 0 else self.elapsed / self.duration
        value = self.start + (self.goal - self.start) * shape_value(self.spec.shape, tau)
        slope = 0.0
        if 0 < self.duration and tau < 1.0:
            nxt = self.start + (self.goal - self.start) * shape_value(self.spec.shape, tau + dt / self.duration)
            slope = (nxt - value) / dt
        st.offset = value
        fwd = self.roads.lane_info(st.road, st.lane, st.s)["forward"]
        dir_s = 1.0 if math.cos(self.base + (0.0 if fwd else math.pi)) > 0 else -1.0
        st.h_rel = self.base + dir_s * math.atan(slope / max(abs(st.speed), 1e-3))
        self.elapsed += dt
        if tau >= 1.0 and not self.spec.continuous:
            self.done = True
            st.h_rel = self.base
        return ("lateral",)


class SpringMove:
    """The damped spring of LongitudinalDistance and LateralDistance, limited."""

    def __init__(self, constraints):
        self.acc_max, self.dec_max, self.v_max, self.jerk_up, self.jerk_down = _limits(constraints)
        self.unlimited = self.acc_max >= BIG and self.dec_max >= BIG
        self.acc = 0.0

    def accel(self, error, rel_speed, dt):
        tension = self.acc_max if error < 0 else self.dec_max
        k = tension * SPRING
        acc = error * k - rel_speed * 2.0 * math.sqrt(k)
        if acc < 0:
            acc, jerk = max(acc, -self.dec_max), -self.jerk_down
        else:
            acc, jerk = min(acc, self.acc_max), self.jerk_up
        if jerk < 0 and acc < self.acc:
            acc = max(self.acc + jerk * dt, acc)
        elif jerk > 0 and acc > self.acc:
            acc = min(self.acc + jerk * dt, acc)
        self.acc = acc
        return acc


class LongDistanceMove(SpringMove):
    def __init__(self, spec, st, states, movers):
        super().__init__(spec.constraints)
        self.spec, self.states, self.movers = spec, states, movers
        self.displacement = spec.displacement
        if self.displacement == "any":
            d = self._distance(st)
            self.displacement = "leadingReferencedEntity" if d < 0 else "trailingReferencedEntity"
        self.done = False

    def _distance(self, st):
        ref = self.states[self.spec.entity]
        return g.signed_axis_distance(body(st), body(ref), 0, self.spec.freespace)

    def step(self, st, dt):
        ref = self.states[self.spec.entity]
        d = self._distance(st)
        want = self.spec.distance if self.spec.distance is not None else abs(ref.speed) * self.spec.time_gap
        want = abs(want) if self.displacement == "trailingReferencedEntity" else -abs(want)
        error = d - want
        if not self.spec.continuous and abs(error) < REACHED_M:
            self.done = True
        if self.unlimited:
            self.movers.move_along(st, error)
            st.speed = ref.speed
        else:
            st.speed += self.accel(error, st.speed - ref.speed, dt) * dt
            st.speed = max(-self.v_max, min(self.v_max, st.speed))
        return ()


class LateralDistanceMove(SpringMove):
    def __init__(self, spec, st, states, roads):
        super().__init__(spec.constraints)
        self.spec, self.states, self.roads = spec, states, roads
        self.v_lat = 0.0
        self.done = False

    def step(self, st, dt):
        if st.road is None:
            return ()
        ref = self.states[self.spec.entity]
        d = g.signed_axis_distance(body(ref), body(st), 1, self.spec.freespace)
        want = self.spec.distance or 0.0
        side = self.spec.displacement
        if side == "any":
            side = "leftToReferencedEntity" if d >= 0 else "rightToReferencedEntity"
        want = abs(want) if side == "leftToReferencedEntity" else -abs(want)
        error = want - d    # how far it has to move to its left
        if self.unlimited and self.v_max >= BIG:
            shift = error
        elif self.unlimited:   # only a speed limit: straight there at most that fast
            shift = max(-self.v_max * dt, min(self.v_max * dt, error))
        else:
            self.v_lat += self.accel(error, self.v_lat, dt) * dt
            self.v_lat = max(-self.v_max, min(self.v_max, self.v_lat))
            shift = self.v_lat * dt
        ref_fwd = self.roads.lane_info(ref.road, ref.lane, ref.s)["forward"] if ref.road else True
        faces_s = math.cos(ref.h_rel + (0.0 if ref_fwd else math.pi)) > 0
        st.offset += shift if faces_s else -shift
        if not self.spec.continuous and abs(error) < REACHED_M:
            self.done = True
        return ("lateral",)


class SynchronizeMove:
    def __init__(self, spec, st, states, place):
        self.spec, self.states = spec, states
        self.master_xy = place(spec.master_position)[:2]
        self.target_xy = place(spec.position)[:2]
        self.tol_master = spec.tolerance_master or SYNC_TOLERANCE_M
        self.done = False

    def step(self, st, dt):
        master = self.states[self.spec.master]
        dm = math.hypot(self.master_xy[0] - master.x, self.master_xy[1] - master.y)
        d = math.hypot(self.target_xy[0] - st.x, self.target_xy[1] - st.y)
        fs = self.spec.final_speed
        vf = None
        if fs is not None:
            if fs.kind == "absolute":
                vf = fs.value
            else:
                vf = master.speed + fs.value if fs.value_type == "delta" else master.speed * fs.value
        if dm < self.tol_master or abs(master.speed) < 1e-6:
            if dm < self.tol_master:
                self.done = True
                if vf is not None:
                    st.speed = vf
            return ()
        tm = dm / abs(master.speed)
        if vf is None:
            st.speed = d / tm
        else:
            st.speed = max(0.0, 2.0 * d / tm - vf) if tm > dt else vf
        return ()


class SpeedProfileMove:
    def __init__(self, spec, st, states, perf_limits):
        self.spec = spec
        offset = states[spec.entity].speed if spec.entity else 0.0
        acc_max, dec_max, _, _, _ = _limits(spec.constraints)
        acc_max, dec_max = min(acc_max, perf_limits[0]), min(dec_max, perf_limits[1])
        self.points = [(0.0, st.speed)]     # (time since start, speed)
        t, v = 0.0, st.speed
        for e in spec.entries:
            target = e.speed + offset
            if e.time is not None and e.time > 0:
                t += e.time
            elif e.time is not None:
                if spec.following_mode == "position":
                    self.points.append((t, target))
                v = target
                continue
            else:
                rate = acc_max if target > v else dec_max
                t += abs(target - v) / rate if rate < BIG else 0.0
            self.points.append((t, target))
            v = target
        self.elapsed = 0.0
        self.done = False

    def step(self, st, dt):
        self.elapsed += dt
        pts = self.points
        if self.elapsed >= pts[-1][0]:
            st.speed = pts[-1][1]
            self.done = True
            return ()
        i = 0
        while i < len(pts) - 2 and pts[i + 1][0] <= self.elapsed:
            i += 1
        (t0, v0), (t1, v1) = pts[i], pts[i + 1]
        st.speed = v1 if t1 <= t0 else v0 + (v1 - v0) * (self.elapsed - t0) / (t1 - t0)
        return ()
