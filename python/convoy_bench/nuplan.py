"""nuPlan's closed-loop metrics, as score.py combines them (docs/scoring.md, "nuPlan-style
score"). Definitions follow motional/nuplan-devkit: nuplan/planning/metrics/evaluation_metrics/
common/ (no_ego_at_fault_collisions.py, time_to_collision_within_bound.py,
speed_limit_compliance.py, ego_progress_along_expert_route.py, ego_is_comfortable.py,
driving_direction_compliance.py, drivable_area_compliance.py), the thresholds of
nuplan/planning/script/config/common/simulation_metric/ and the weights of
config/simulation/metric_aggregator/closed_loop_reactive_agents_weighted_average.yaml. Written
here from those definitions; where Convoy's data differ, the simplification is stated.

- At-fault collisions (nuPlan's classification, first contact with each other road user):
  the ego stopped (speed <= 0.05 m/s) -> "stopped_ego", not at fault; else the other stopped
  (<= 0.05 m/s, or a static object) -> "stopped_track", at fault; else the other's centre behind
  the ego (more than 150 deg off the ego's heading, seen from the ego's reference point) ->
  "active_rear", not at fault; else the ego's front edge meets the other's box ->
  "active_front", at fault; else "active_lateral", at fault only while the ego is in more than
  one lane or off the drivable area. Score: per category max(0, 1 - n / (allowed + 1)), allowed
  0 for VRUs (pedestrians, cyclists), 0 for vehicles, 1 for objects; the product.
- TTC: ego and others projected at constant speed and heading in 0.1 s steps to 3 s (steps
  0.1 .. 2.9 s, as np.arange(0.1, 3.0, 0.1)); the TTC of a sample is the first step at which the
  boxes overlap. Others considered: those ahead (within 30 deg of the ego's heading), and, while
  the ego is in more than one lane, in a junction or off the road, all not behind (> 150 deg).
  None when the ego is stopped (<= 0.005 m/s) or nothing is met. 0 at an at-fault collision.
  Within bound: every TTC > 0.95 s (nuPlan's strict test).
- Comfort: derivatives by Savitzky-Golay fits over the same time spans as nuPlan's windows at
  its 10 Hz (acceleration 0.7 s, jerk 1.4 s, yaw 0.4 s; an odd number of samples, at least 5,
  at most the trajectory's). Longitudinal acceleration d(speed)/dt (poly 2); lateral acceleration speed x
  yaw rate, smoothed (poly 2); longitudinal jerk d(lon. acc.)/dt; jerk magnitude
  d|acc|/dt (poly 2); yaw rate d(yaw)/dt (poly 2); yaw acceleration d2(yaw)/dt2 (poly 3). Within
  bound strictly: lon. acc. in (-4.05, 2.40) m/s2, |lat. acc.| < 4.89 m/s2, |lon. jerk| < 4.13
  m/s3, |jerk| < 8.37 m/s3, |yaw rate| < 0.95 rad/s, |yaw acc.| < 1.93 rad/s2. nuPlan reads the
  accelerations from the simulator's state; here they come from speed and heading.
"""

import math

import numpy as np

from . import geometry

STOPPED_SPEED = 0.05          # m/s, nuPlan's stopped_speed_threshold for collisions
TTC_STOPPED_SPEED = 0.005     # m/s, nuPlan's compute_time_to_collision default
REAR_ANGLE = math.radians(150.0)
AHEAD_ANGLE = math.radians(30.0)
COLLISION_ALLOWED = {"vru": 0, "vehicle": 0, "object": 1}
TTC_STEP = 0.1
TTC_HORIZON = 3.0
LEAST_MIN_TTC = 0.95
SPEED_LIMIT_MAX_OVERSPEED = 2.23   # m/s
PROGRESS_THRESHOLD_M = 2.0
MIN_PROGRESS_RATIO = 0.2
DIRECTION_COMPLIANCE_M = 2.0
DIRECTION_VIOLATION_M = 6.0
DIRECTION_HORIZON_S = 1.0
WEIGHTS = (("ego_progress_along_expert_route", 5.0), ("time_to_collision_within_bound", 5.0),
           ("speed_limit_compliance", 4.0), ("ego_is_comfortable", 2.0))
COMFORT_BOUNDS = {  # (low, high), strict
    "lon_acceleration": (-4.05, 2.40), "lat_acceleration": (-4.89, 4.89),
    "lon_jerk": (-4.13, 4.13), "jerk": (-8.37, 8.37),
    "yaw_rate": (-0.95, 0.95), "yaw_acceleration": (-1.93, 1.93)}
WINDOW_SPANS_S = {"acceleration": 0.7, "jerk": 1.4, "yaw": 0.4}
# Box sizes (m) when a road user gives none: length, width.
DEFAULT_SIZE = {"car": (4.5, 1.8), "truck": (8.0, 2.5), "bus": (12.0, 2.55),
                "pedestrian": (0.5, 0.5), "cyclist": (1.8, 0.6)}
VRU_CLASSES = ("pedestrian", "cyclist", "bicycle")


# --- comfort -------------------------------------------------------------------------------

def window_samples(span_s, dt, n):
    """Samples in a window spanning span_s seconds at step dt: odd, at least 5 (nuPlan's
    smallest window), at most n (odd)."""
    w = max(5, int(round(span_s / dt)) + 1)
    if w % 2 == 0:
        w += 1
    if w > n:
        w = n if n % 2 == 1 else n - 1
    return w


def savgol(y, window, poly, deriv, delta):
    """Savitzky-Golay filter (scipy's savgol_filter with mode 'interp'): the deriv-th
    derivative of the least-squares polynomial of degree poly over each centred window of
    `window` (odd) samples at spacing delta; the first and last window // 2 samples from the
    polynomial fitted to the first and last `window` samples."""
    y = np.asarray(y, float)
    n, m = len(y), window // 2
    if window % 2 != 1 or window > n or poly >= window:
        raise ValueError("savgol: window %d, poly %d, %d samples" % (window, poly, n))
    k = np.arange(-m, m + 1, dtype=float)
    vander = k[:, None] ** np.arange(poly + 1)[None, :]
    coeffs = np.linalg.pinv(vander)[deriv] * math.factorial(deriv) / delta ** deriv
    out = np.empty(n)
    if n > 2 * m:
        windows = np.lib.stride_tricks.sliding_window_view(y, window)
        out[m:n - m] = windows @ coeffs
    pos = np.arange(window, dtype=float)
    vpos = pos[:, None] ** np.arange(poly + 1)[None, :]
    for first, last in ((0, m), (n - m, n)):            # out[first:last] from an end's window
        start = 0 if first == 0 else n - window
        c = np.linalg.lstsq(vpos, y[start:start + window], rcond=None)[0]
        dc = np.polynomial.polynomial.polyder(c, deriv) if deriv else c
        out[first:last] = np.polynomial.polynomial.polyval(pos[first - start:last - start], dc) / delta ** deriv
    return out


def comfort(t, speed, yaw):
    """The comfort metrics of a trajectory: {metric: {"min", "max", "within_bound"}} and
    whether all are within bound. With fewer than 5 samples nothing is measured: ({}, True)."""
    t, speed = np.asarray(t, float), np.asarray(speed, float)
    n = len(t)
    if n < 5:
        return {}, True
    dt = float(np.mean(np.diff(t)))
    wa = window_samples(WINDOW_SPANS_S["acceleration"], dt, n)
    wj = window_samples(WINDOW_SPANS_S["jerk"], dt, n)
    wy = window_samples(WINDOW_SPANS_S["yaw"], dt, n)
    yaw_u = np.unwrap(np.asarray(yaw, float))
    lon_acc = savgol(speed, wa, 2, 1, dt)
    yaw_rate = savgol(yaw_u, wy, 2, 1, dt)
    yaw_acc = savgol(yaw_u, wy, 3, 2, dt) if wy > 3 else np.zeros(n)
    lat_acc = savgol(speed * yaw_rate, wa, 2, 0, dt)
    series = {"lon_acceleration": lon_acc, "lat_acceleration": lat_acc,
              "lon_jerk": savgol(lon_acc, wj, 2, 1, dt),
              "jerk": savgol(np.hypot(lon_acc, lat_acc), wj, 2, 1, dt),
              "yaw_rate": yaw_rate, "yaw_acceleration": yaw_acc}
    out = {}
    for name in sorted(COMFORT_BOUNDS):
        lo, hi = COMFORT_BOUNDS[name]
        v = series[name]
        out[name] = {"min": float(v.min()), "max": float(v.max()),
                     "within_bound": bool(np.all((v > lo) & (v < hi)))}
    return out, all(e["within_bound"] for e in out.values())


# --- collisions ----------------------------------------------------------------------------

def size_of(state, cls=None):
    """(length, width, length_offset) of a road user's state dict, by class when missing."""
    cls = state.get("class", cls) or "car"
    dl, dw = DEFAULT_SIZE.get(cls, DEFAULT_SIZE["car"])
    return (float(state.get("length") or dl), float(state.get("width") or dw),
            float(state.get("length_offset") or 0.0))


def collision_type(ego, other, static=False):
    """nuPlan's collision type of the ego's state {"x", "y", "yaw", "speed", "length",
    "width", "length_offset"} against the other's (same keys; None when unknown). A static
    object counts as a stopped track. Unknown other state of a moving ego: "unknown"."""
    if float(ego["speed"]) <= STOPPED_SPEED:
        return "stopped_ego"
    if static or (other is not None and abs(float(other.get("speed", 0.0))) <= STOPPED_SPEED):
        return "stopped_track"
    if other is None:
        return "unknown"
    ol, ow, ooff = size_of(other)
    oyaw = float(other.get("yaw", 0.0))
    ocx = float(other["x"]) + ooff * math.cos(oyaw)
    ocy = float(other["y"]) + ooff * math.sin(oyaw)
    if geometry.relative_angle(float(ego["x"]), float(ego["y"]), float(ego["yaw"]), ocx, ocy) > REAR_ANGLE:
        return "active_rear"
    el, ew, eoff = size_of(ego, "car")
    ec = geometry.box_corners(ego["x"], ego["y"], ego["yaw"], el, ew, eoff)
    oc = geometry.box_corners(other["x"], other["y"], oyaw, ol, ow, ooff)
    if geometry.segment_hits_box(ec[0], ec[3], oc):
        return "active_front"
    return "active_lateral"


def is_at_fault(ctype, ego_in_multiple_lanes_or_off_road):
    """nuPlan's at-fault rule for a collision type; "unknown" counts as at fault."""
    if ctype in ("stopped_track", "active_front", "unknown"):
        return True
    return ctype == "active_lateral" and bool(ego_in_multiple_lanes_or_off_road)


def collision_category(kind, other_class=None):
    """nuPlan's category of a collision: "vru", "vehicle" or "object"."""
    if kind == "collision_pedestrian" or other_class in VRU_CLASSES:
        return "vru"
    return "object" if kind == "collision_static" else "vehicle"


def at_fault_collision_score(counts):
    """Product over categories of max(0, 1 - n / (allowed + 1))."""
    score = 1.0
    for cat in ("vru", "vehicle", "object"):
        score *= max(0.0, 1.0 - counts.get(cat, 0) / (COLLISION_ALLOWED[cat] + 1))
    return score


# --- time to collision ---------------------------------------------------------------------

def ttc_at(ego, others, wide=False):
    """nuPlan's TTC (s) of the ego state against other road users' states (list of dicts with
    "x", "y", "yaw", "speed", optional "class", "length", "width", "length_offset"). `wide`: the
    ego is in more than one lane, in a junction or off the road (lateral others count too).
    None when the ego is stopped or no overlap happens within the horizon."""
    speed = float(ego["speed"])
    if speed <= TTC_STOPPED_SPEED or not others:
        return None
    ex, ey, eyaw = float(ego["x"]), float(ego["y"]), float(ego["yaw"])
    el, ew, eoff = size_of(ego, "car")
    steps = np.arange(1, int(round(TTC_HORIZON / TTC_STEP)), dtype=float) * TTC_STEP
    reach = speed * TTC_HORIZON + el + abs(eoff)
    rows = []
    for o in others:
        ol, ow, ooff = size_of(o)
        oyaw, ospeed = float(o.get("yaw", 0.0)), float(o.get("speed", 0.0))
        ox, oy = float(o["x"]), float(o["y"])
        cx, cy = ox + ooff * math.cos(oyaw), oy + ooff * math.sin(oyaw)
        if math.hypot(cx - ex, cy - ey) > reach + abs(ospeed) * TTC_HORIZON + ol + abs(ooff):
            continue
        ang = geometry.relative_angle(ex, ey, eyaw, cx, cy)
        if not (ang < AHEAD_ANGLE or (wide and ang <= REAR_ANGLE)):
            continue
        rows.append((ox, oy, oyaw, ospeed, ol, ow, ooff))
    if not rows:
        return None
    o = np.array(rows, float)
    ego_box = geometry.box_corners(ex + speed * math.cos(eyaw) * steps, ey + speed * math.sin(eyaw) * steps,
                                   eyaw, el, ew, eoff)                     # (S, 4, 2)
    ox = o[:, None, 0] + (o[:, 3] * np.cos(o[:, 2]))[:, None] * steps[None, :]
    oy = o[:, None, 1] + (o[:, 3] * np.sin(o[:, 2]))[:, None] * steps[None, :]
    boxes = geometry.box_corners(ox, oy, o[:, None, 2], o[:, None, 4], o[:, None, 5], o[:, None, 6])
    hit = geometry.boxes_overlap(ego_box[None], boxes).any(axis=0)      # (S,)
    if not hit.any():
        return None
    return round(float(steps[int(np.argmax(hit))]), 9)


# --- the other metrics ---------------------------------------------------------------------

def speed_limit_compliance(t, speed, limits):
    """max(0, 1 - sum(overspeed) * mean dt / (2.23 m/s * duration)); samples without a limit
    (None) do not violate. 1 for a zero duration."""
    t = np.asarray(t, float)
    duration = float(t[-1] - t[0]) if len(t) else 0.0
    if duration <= 0.0:
        return 1.0, 0.0
    over = [max(0.0, float(v) - float(lim)) if lim is not None else 0.0 for v, lim in zip(speed, limits)]
    dt = float(np.mean(np.diff(t)))
    loss = math.fsum(over) * dt / (max(SPEED_LIMIT_MAX_OVERSPEED, 1e-3) * duration)
    return max(0.0, 1.0 - loss), max(over) if over else 0.0


def driving_direction_compliance(t, x, y, wrong_way, extra_m=()):
    """nuPlan's driving-direction score from per-sample wrong-way flags: a sample's movement
    (distance from the previous sample) counts against the lane's direction when flagged, for
    it otherwise; the worst sum over the last 1 s (samples i - n .. i, n = int(1 s / mean dt))
    below zero, with the given extra distances (m), gives 1 (< 2 m), 0.5 (< 6 m) or 0."""
    n = len(t)
    prog = [0.0]
    for i in range(1, n):
        d = math.hypot(x[i] - x[i - 1], y[i] - y[i - 1])
        prog.append(-d if wrong_way[i] else d)
    horizon = int(DIRECTION_HORIZON_S / float(np.mean(np.diff(t)))) if n > 1 else 0
    sums = [math.fsum(prog[max(0, i - horizon):i + 1]) for i in range(n)]
    worst = max([max(0.0, -min(sums))] + [float(e) for e in extra_m])
    if worst < DIRECTION_COMPLIANCE_M:
        return 1.0, worst
    return (0.5 if worst < DIRECTION_VIOLATION_M else 0.0), worst


def progress_ratio(ego_progress_m, expert_progress_m):
    """nuPlan's ego-to-expert progress ratio: 0 below -2 m, else
    min(1, max(ego, 2 m) / max(expert, 2 m))."""
    if ego_progress_m < -PROGRESS_THRESHOLD_M:
        return 0.0
    return min(1.0, max(ego_progress_m, PROGRESS_THRESHOLD_M) / max(expert_progress_m, PROGRESS_THRESHOLD_M))


def combine(multipliers, weighted):
    """The closed-loop score: product of the multipliers x weighted mean of the weighted
    metrics (WEIGHTS)."""
    m = 1.0
    for name in ("no_ego_at_fault_collisions", "drivable_area_compliance",
                 "driving_direction_compliance", "ego_is_making_progress"):
        m *= multipliers[name]
    total = math.fsum(w for _, w in WEIGHTS)
    return m * math.fsum(w * weighted[name] for name, w in WEIGHTS) / total
