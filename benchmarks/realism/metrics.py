"""Distributions a traffic engineer checks, from a trace (traces.py), the same way for every
source: time headways, speed against the limit, acceleration, jerk, accepted gaps at junctions
and flows at measuring points. Each metric is a 1-D array of samples (summary() gives
percentiles and the mean); ks() is the two-sample Kolmogorov-Smirnov distance.
"""
import numpy as np

MOVING = 2.0  # m/s: headways of followers (and speeds) above this only
SMOOTH = 5    # samples in the centred moving average of speed before differencing
MAX_GAP_S = 60.0  # accepted gaps longer than this are not counted (nobody in conflict)


def time_headways(tr):
    """Gap (rear of the leader to the front of the follower, same lane, same instant) over the
    follower's speed, for followers moving > MOVING m/s. s"""
    order = np.lexsort((tr["s"], tr["lane"], tr["t"]))
    t, lane, s, v, ln = (tr[k][order] for k in ("t", "lane", "s", "speed", "length"))
    same = (t[1:] == t[:-1]) & (lane[1:] == lane[:-1])
    gap = s[1:] - ln[1:] - s[:-1]  # row k+1 leads row k
    vf = v[:-1]
    keep = same & (vf > MOVING) & (gap > 0)
    return gap[keep] / vf[keep]


def speed_over_limit(tr):
    """Speed minus the lane's limit, m/s, for vehicles moving > MOVING m/s."""
    keep = tr["speed"] > MOVING
    return tr["speed"][keep] - tr["limit"][keep]


def _runs(tr):
    """(start, end) row ranges of each vehicle's samples."""
    vid = tr["vid"]
    cut = np.flatnonzero(vid[1:] != vid[:-1]) + 1
    starts = np.concatenate(([0], cut))
    ends = np.concatenate((cut, [len(vid)]))
    return zip(starts, ends)


def accel_jerk(tr):
    """Longitudinal acceleration (m/s^2) and jerk (m/s^3) from speeds at the sample rate, the
    speed smoothed by a centred moving average of SMOOTH samples; a vehicle's samples must be
    evenly spaced (a gap in them starts a new piece)."""
    acc, jerk = [], []
    kernel = np.ones(SMOOTH) / SMOOTH
    for a, b in _runs(tr):
        t, v = tr["t"][a:b], tr["speed"][a:b]
        if len(t) < SMOOTH + 2:
            continue
        dt = np.diff(t)
        step = np.median(dt)
        pieces = np.split(np.arange(len(t)), np.flatnonzero(np.abs(dt - step) > 1e-6) + 1)
        for p in pieces:
            if len(p) < SMOOTH + 2:
                continue
            vs = np.convolve(v[p], kernel, mode="valid")
            ac = np.diff(vs) / step
            acc.append(ac)
            jerk.append(np.diff(ac) / step)
    cat = lambda xs: np.concatenate(xs) if xs else np.zeros(0)
    return cat(acc), cat(jerk)


def junction_entries(tr):
    """(time, junction, heading) of every entry into a junction: a vehicle's first sample inside
    it after one outside; the heading (rad) from its first to its last sample on the approach."""
    j, road, vid, x, y = (tr[k] for k in ("junction", "road", "vid", "x", "y"))
    n = len(j)
    new_run = np.ones(n, dtype=bool)
    new_run[1:] = (vid[1:] != vid[:-1]) | (road[1:] != road[:-1])
    run_start = np.maximum.accumulate(np.where(new_run, np.arange(n), 0))
    k = np.flatnonzero((j[1:] >= 0) & (j[:-1] < 0) & (vid[1:] == vid[:-1])) + 1
    a, b = run_start[k - 1], k - 1
    dx, dy = x[b] - x[a], y[b] - y[a]
    seen = np.hypot(dx, dy) > 3  # an approach seen over 3 m at least
    return tr["t"][k][seen], j[k][seen], np.arctan2(dy, dx)[seen]


def accepted_gaps(tr):
    """Per junction entry, the time to the nearest entry (before or after) into the same
    junction by a vehicle of a crossing stream (its approach heading 45-135 degrees off): the
    gap in the crossing traffic it entered in. s"""
    t, j, heading = junction_entries(tr)
    out = []
    for jj in np.unique(j):
        m = j == jj
        tt, hh = t[m], heading[m]
        for k in range(len(tt)):
            off = np.abs((hh - hh[k] + np.pi / 2) % np.pi - np.pi / 2)  # 0..pi/2, mod 180 deg
            other = tt[off > np.pi / 4]
            if len(other):
                g = np.min(np.abs(other - tt[k]))
                if g <= MAX_GAP_S:
                    out.append(g)
    return np.asarray(out)


def flows(tr, duration_s):
    """Vehicles per hour on each road outside junctions (distinct vehicles seen on it)."""
    names = tr["names"]["roads"]
    keep = tr["road"] >= 0
    pairs = np.unique(np.stack((tr["road"][keep], tr["vid"][keep]), axis=1), axis=0)
    roads, counts = np.unique(pairs[:, 0], return_counts=True)
    return {names[r]: 3600.0 * c / duration_s for r, c in zip(roads, counts)}


def summary(x):
    x = np.asarray(x, dtype=float)
    if len(x) == 0:
        return {"n": 0}
    p = np.percentile(x, [5, 25, 50, 75, 95])
    return {"n": int(len(x)), "mean": float(np.mean(x)),
            **{"p%d" % q: float(v) for q, v in zip((5, 25, 50, 75, 95), p)}}


def ks(a, b):
    """Two-sample Kolmogorov-Smirnov distance: the largest gap between the two ECDFs."""
    a, b = np.sort(np.asarray(a, float)), np.sort(np.asarray(b, float))
    if len(a) == 0 or len(b) == 0:
        return float("nan")
    x = np.concatenate((a, b))
    fa = np.searchsorted(a, x, side="right") / len(a)
    fb = np.searchsorted(b, x, side="right") / len(b)
    return float(np.max(np.abs(fa - fb)))


def all_metrics(tr, duration_s):
    acc, jerk = accel_jerk(tr)
    return {
        "time_headway_s": time_headways(tr),
        "speed_minus_limit_mps": speed_over_limit(tr),
        "acceleration_mps2": acc,
        "jerk_mps3": jerk,
        "accepted_gap_s": accepted_gaps(tr),
    }, flows(tr, duration_s)
