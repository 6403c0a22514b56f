"""Driving scores of one drive, the project's one definition (docs/scoring.md): the CARLA
Leaderboard 2.0 driving score and a nuPlan-style closed-loop score.

Inputs are plain dicts and lists:
- trajectory: the ego's samples in increasing time, each {"t", "x", "y", "yaw", "speed"} (s, m,
  rad, m/s), optionally "on_route", "on_road", "wrong_way" (missing: True, True, False),
  "multiple_lanes", "in_junction" (nuPlan's at-fault and TTC rules; missing: False), "road",
  "lane" (ids, not used), "speed_limit" (m/s, None: unknown), "ttc" (s, nuPlan's TTC, None: no
  conflict within 3 s; nuplan.ttc_at computes it), "traffic_speed" (mean speed of the other
  vehicles, m/s, None: none) and the ego's box "length", "width", "length_offset".
- route: {"points": [[x, y], ...]} (the polyline the ego should drive, starting where it
  starts), optionally "length" (m; must match the polyline's within 1 mm) and
  "expert_progress_m" (nuPlan's expert progress; default the route's length ahead of the ego's
  first position).
- events: [{"t", "kind", "other", ...}], kind one of KINDS; optionally "percentage"
  (min_speed: the ego's speed in % of the traffic's), "distance_m" (off_route, off_road,
  wrong_way: route distance driven so), "ego_speed", "other_class", "other_state" {"x", "y",
  "yaw", "speed", "length", "width", "length_offset"} and "collision_type" (nuPlan's, forced).
- speed_limits: optional list aligned with the trajectory (overrides "speed_limit").

CARLA Leaderboard 2.0 (carla-simulator/leaderboard, branch leaderboard-2.0,
leaderboard/utils/statistics_manager.py: PENALTY_VALUE_DICT, PENALTY_PERC_DICT,
compute_route_statistics; carla-simulator/scenario_runner, branch leaderboard-2.0,
srunner/scenariomanager/scenarioatomics/atomic_criteria.py: RouteCompletionTest,
OutsideRouteLanesTest, CollisionTest, MinimumSpeedRouteTest, ActorBlockedTest, InRouteTest;
leaderboard/scenarios/route_scenario.py: checkpoints=4, blocked 180 s below 0.1 m/s):
- DS = RC x P. P = the product of the counted infractions' factors, taken in (t, kind, other)
  order: collision_pedestrian 0.50, collision_vehicle 0.60, collision_static 0.65, red_light
  0.70, stop_sign 0.80, scenario_timeout 0.70, yield_emergency 0.70, min_speed
  1 - 0.3 (1 - min(pct, 100) / 100); off_route, off_road, wrong_way and agent_blocked 1 (they
  act on RC). Every collision event counts once, except, as CARLA's CollisionTest, one while
  the ego's speed is below 0.1 m/s (the event's "ego_speed", else the last sample at or
  before t). No other de-duplication.
- Route progress s: the first sample's nearest point on the whole route, then for each sample
  the nearest point on the route between s - 10 m and s + 50 m; s only grows; a sample more
  than 30 m from the route, or after the ego was blocked, makes none. RC_raw = 100 s / L (L the
  route's length), or 100 once a sample has 100 s / L > 99 within 10 m of the route's end.
- Outside route lanes: progress made at samples with on_route False, on_road False or
  wrong_way True, plus the events' distance_m, is d_off (at most s). RC = RC_raw (1 - d_off / s):
  without the finish rule, 100 (s - d_off) / L, the route length completed in the route's
  lanes. (The Leaderboard multiplies its penalty by 1 - d_off / s instead; DS is the same.)
- min_speed, computed when samples carry traffic_speed: the route in 4 parts; a checkpoint closes
  when s passes the last one by more than L / 4, and at the end when s / L > 0.95; its value is
  round(100 mean(ego speed) / mean(traffic speed), 2) over the samples with a traffic speed
  since the last checkpoint (100 without one); below 100 it is an infraction.
- agent_blocked, computed: speed below 0.1 m/s for 180 s in a row; the route ends there.
CARLA's RC follows route waypoints and rounds to 2 decimals; here the projection is continuous
and nothing is rounded.

The nuPlan-style score and its metrics: nuplan.py. Scores depend only on the inputs' values:
sums are math.fsum, products in sorted order, so equal inputs give bit-identical results.

CLI: /usr/bin/python3 -m convoy_bench.score RUN_DIR [--route CSV] prints the JSON of a
city_traffic run folder (runs.score_run).
"""

import argparse
import bisect
import json
import math
import sys

import numpy as np

from . import geometry, nuplan

PENALTY = {"collision_pedestrian": 0.50, "collision_vehicle": 0.60, "collision_static": 0.65,
           "red_light": 0.70, "stop_sign": 0.80, "scenario_timeout": 0.70,
           "yield_emergency": 0.70}
MIN_SPEED_WEIGHT = 0.3           # 1 - PENALTY_PERC_DICT's 0.7
ROUTE_KINDS = ("off_route", "off_road", "wrong_way")
KINDS = tuple(sorted(PENALTY)) + ("min_speed",) + ROUTE_KINDS + ("agent_blocked",)
COLLISION_KINDS = ("collision_pedestrian", "collision_static", "collision_vehicle")
CARLA_STOPPED_SPEED = 0.1        # m/s, CollisionTest.EPSILON
PROJECTION_BACK_M = 10.0
PROJECTION_AHEAD_M = 50.0
ROUTE_DEVIATION_M = 30.0         # InRouteTest offroad_max
FINISH_PERCENT = 99.0            # RouteCompletionTest.PERCENTAGE_THRESHOLD
FINISH_DISTANCE_M = 10.0         # RouteCompletionTest.DISTANCE_THRESHOLD
MIN_SPEED_CHECKPOINTS = 4
MIN_SPEED_END_FRACTION = 0.95
BLOCKED_SPEED = 0.1
BLOCKED_TIME_S = 180.0


# --- inputs --------------------------------------------------------------------------------

def _samples(trajectory):
    if not isinstance(trajectory, (list, tuple)) or len(trajectory) < 2:
        raise ValueError("trajectory: need a list of at least two samples")
    out = []
    for i, s in enumerate(trajectory):
        try:
            d = dict(s)
            for k in ("t", "x", "y", "yaw", "speed"):
                d[k] = float(s[k])
                if not math.isfinite(d[k]):
                    raise ValueError("%s is not finite" % k)
        except (KeyError, TypeError, ValueError) as e:
            raise ValueError("trajectory sample %d: %s" % (i, e)) from None
        if out and d["t"] <= out[-1]["t"]:
            raise ValueError("trajectory sample %d: time %g not after %g" % (i, d["t"], out[-1]["t"]))
        out.append(d)
    return out


def _events(events):
    out = []
    for i, e in enumerate(events or ()):
        try:
            d = dict(e)
            d["t"] = float(e["t"])
            d["kind"] = str(e["kind"])
        except (KeyError, TypeError, ValueError) as err:
            raise ValueError("event %d: %s" % (i, err)) from None
        if d["kind"] not in KINDS:
            raise ValueError("event %d: unknown kind %r (one of %s)" % (i, d["kind"], ", ".join(KINDS)))
        d["other"] = None if e.get("other") is None else str(e["other"])
        out.append(d)
    return out


def _event_key(e):
    return (e["t"], e["kind"], e["other"] or "", float(e.get("percentage") or 0.0),
            float(e.get("distance_m") or 0.0))


def _outside_kind(sample):
    """The kind of route-lane infraction a sample is in, or None."""
    if sample.get("on_road") is False:
        return "off_road"
    if sample.get("wrong_way") is True:
        return "wrong_way"
    if sample.get("on_route") is False:
        return "off_route"
    return None


def _state_at(samples, times, t):
    """The last sample at or before t (the first one before the trajectory starts)."""
    return samples[max(0, bisect.bisect_right(times, t) - 1)]


# --- CARLA ---------------------------------------------------------------------------------

def blocked_time(samples):
    """When the ego has been below 0.1 m/s for 180 s in a row, or None."""
    start = None
    for s in samples:
        if s["speed"] < BLOCKED_SPEED:
            start = s["t"] if start is None else start
            if s["t"] - start >= BLOCKED_TIME_S:
                return s["t"]
        else:
            start = None
    return None


def route_progress(samples, route, end_t=None):
    """Per-sample route projections and the route completion terms (module docstring)."""
    pts, cum = geometry.route_polyline(route)
    L = float(cum[-1])
    given = route.get("length") if isinstance(route, dict) else None
    if given is not None and abs(float(given) - L) > 1e-3:
        raise ValueError("route: length %g does not match its points (%g m)" % (float(given), L))
    proj, s_max, finished = [], 0.0, False
    off_m, stretches, max_offset = [], [], 0.0
    end_x, end_y = pts[-1]
    for i, smp in enumerate(samples):
        if i == 0:
            s, dist, _ = geometry.project_on_polyline(pts, cum, smp["x"], smp["y"])
        else:
            s, dist, _ = geometry.project_on_polyline(pts, cum, smp["x"], smp["y"],
                                                      s_max - PROJECTION_BACK_M, s_max + PROJECTION_AHEAD_M)
        proj.append(s)
        if end_t is None or smp["t"] <= end_t:
            max_offset = max(max_offset, dist)
        if (end_t is not None and smp["t"] > end_t) or dist > ROUTE_DEVIATION_M:
            continue
        gain = max(0.0, s - s_max) if i else s
        s_max = max(s_max, s)
        kind = _outside_kind(smp) if i else None
        if kind is not None:
            off_m.append(gain)
            if stretches and stretches[-1]["kind"] == kind and stretches[-1]["_last"] == i - 1:
                stretches[-1]["distance_m"].append(gain)
                stretches[-1]["_last"] = i
            else:
                stretches.append({"t": smp["t"], "kind": kind, "distance_m": [gain], "_last": i})
        if 100.0 * s_max / L > FINISH_PERCENT and math.hypot(smp["x"] - end_x, smp["y"] - end_y) < FINISH_DISTANCE_M:
            finished = True
    stretches = [{"t": st["t"], "kind": st["kind"], "distance_m": math.fsum(st["distance_m"])}
                 for st in stretches if math.fsum(st["distance_m"]) > 0.0]
    return {"length": L, "projection": proj, "progress": s_max, "finished": finished,
            "off_flags_m": math.fsum(off_m), "stretches": stretches, "max_offset_m": max_offset}


def min_speed_events(samples, progress, length):
    """CARLA's MinimumSpeedRouteTest over samples carrying "traffic_speed" (module docstring)."""
    checkpoint = length / MIN_SPEED_CHECKPOINTS
    out, current = [], 0.0
    mean, ego, points = 0.0, 0.0, 0

    def close(t):
        if points > 0 and mean:
            pct = round(ego / points / (mean / points) * 100.0, 2)
        else:
            pct = 100.0
        if pct < 100.0:
            out.append({"t": t, "kind": "min_speed", "other": None, "percentage": pct})

    for smp, s in zip(samples, progress):
        if s - current > checkpoint:
            close(smp["t"])
            current, mean, ego, points = s, 0.0, 0.0, 0
        ts = smp.get("traffic_speed")
        if ts is not None:
            mean += float(ts)
            ego += smp["speed"]
            points += 1
    if progress and progress[-1] / length > MIN_SPEED_END_FRACTION:
        close(samples[-1]["t"])
    return out


def infraction_factor(e):
    """The factor an infraction multiplies the penalty by."""
    if e["kind"] == "min_speed":
        pct = min(float(e.get("percentage", 100.0)), 100.0)
        return 1.0 - MIN_SPEED_WEIGHT * (1.0 - pct / 100.0)
    return PENALTY.get(e["kind"], 1.0)


def _carla(samples, times, route, events):
    blocked = [e["t"] for e in events if e["kind"] == "agent_blocked"]
    computed = []
    tb = blocked_time(samples)
    if tb is not None:
        computed.append({"t": tb, "kind": "agent_blocked", "other": None})
        blocked.append(tb)
    end_t = min(blocked) if blocked else None
    rp = route_progress(samples, route, end_t)
    # the monotone progress per sample, frozen after the end, for the minimum-speed test
    running, cur = [], 0.0
    for smp, s in zip(samples, rp["projection"]):
        if end_t is None or smp["t"] <= end_t:
            cur = max(cur, s)
        running.append(cur)
    if any(smp.get("traffic_speed") is not None for smp in samples):
        computed += min_speed_events(samples, running, rp["length"])
    for st in rp["stretches"]:
        computed.append({"t": st["t"], "kind": st["kind"], "other": None, "distance_m": st["distance_m"],
                         "_from_flags": True})
    all_events = sorted(events + computed, key=_event_key)
    L, s = rp["length"], rp["progress"]
    d_off = rp["off_flags_m"] + math.fsum(float(e.get("distance_m") or 0.0) for e in all_events
                                          if e["kind"] in ROUTE_KINDS and not e.get("_from_flags"))
    d_off = min(d_off, s)
    rc_raw = 100.0 if rp["finished"] else 100.0 * s / L
    rc = rc_raw * (1.0 - d_off / s) if s > 0.0 else rc_raw
    penalty, infractions = 1.0, []
    for e in all_events:
        counted = True
        if e["kind"] in COLLISION_KINDS:
            v = e.get("ego_speed")
            v = _state_at(samples, times, e["t"])["speed"] if v is None else float(v)
            counted = v >= CARLA_STOPPED_SPEED
        f = infraction_factor(e) if counted else 1.0
        penalty *= f
        entry = {"t": e["t"], "kind": e["kind"], "other": e["other"], "penalty": f, "counted": counted}
        for k in ("percentage", "distance_m"):
            if k in e:
                entry[k] = float(e[k])
        infractions.append(entry)
    return {"driving_score": rc * penalty, "route_completion": rc, "route_completion_raw": rc_raw,
            "infraction_penalty": penalty, "infractions": infractions, "route_length_m": L,
            "route_progress_m": s, "off_route_m": d_off,
            "off_route_percentage": 100.0 * d_off / s if s > 0.0 else 0.0,
            "route_finished": rp["finished"], "route_ended_at": end_t,
            "route_max_offset_m": rp["max_offset_m"]}, rp


# --- nuPlan --------------------------------------------------------------------------------

def _nuplan(samples, times, route, events, rp, speed_limits):
    t = [s["t"] for s in samples]
    collisions, seen, counts, fault_times = [], set(), {}, []
    for e in sorted((e for e in events if e["kind"] in COLLISION_KINDS), key=_event_key):
        if e["other"] is not None:
            if e["other"] in seen:
                continue
            seen.add(e["other"])
        ego = _state_at(samples, times, e["t"])
        ctype = e.get("collision_type") or nuplan.collision_type(
            ego, e.get("other_state"), static=e["kind"] == "collision_static")
        wide = bool(ego.get("multiple_lanes")) or ego.get("on_road") is False
        at_fault = nuplan.is_at_fault(ctype, wide)
        other_class = e.get("other_class") or (e.get("other_state") or {}).get("class")
        category = nuplan.collision_category(e["kind"], other_class)
        if at_fault:
            counts[category] = counts.get(category, 0) + 1
            fault_times.append(e["t"])
        collisions.append({"t": e["t"], "kind": e["kind"], "other": e["other"], "category": category,
                           "type": ctype, "at_fault": at_fault})
    fault_idx = {max(0, bisect.bisect_right(times, ft) - 1) for ft in fault_times}
    have_ttc = any("ttc" in s for s in samples)
    ttcs = []
    for i, s in enumerate(samples):
        v = 0.0 if i in fault_idx else s.get("ttc")
        if v is not None and math.isfinite(float(v)):
            ttcs.append(float(v))
    min_ttc = min(ttcs) if ttcs else None
    ttc_ok = 1.0 if all(v > nuplan.LEAST_MIN_TTC for v in ttcs) else 0.0

    limits = speed_limits if speed_limits is not None else [s.get("speed_limit") for s in samples]
    if len(limits) != len(samples):
        raise ValueError("speed_limits: %d values for %d samples" % (len(limits), len(samples)))
    speed_score, max_over = nuplan.speed_limit_compliance(t, [s["speed"] for s in samples], limits)
    comfort, comfortable = nuplan.comfort(t, [s["speed"] for s in samples], [s["yaw"] for s in samples])
    direction, worst = nuplan.driving_direction_compliance(
        t, [s["x"] for s in samples], [s["y"] for s in samples],
        [s.get("wrong_way") is True for s in samples],
        [e.get("distance_m") or 0.0 for e in events if e["kind"] == "wrong_way"])
    off_road = any(s.get("on_road") is False for s in samples) or any(e["kind"] == "off_road" for e in events)
    proj = rp["projection"]
    ego_progress = proj[-1] - proj[0]
    expert = route.get("expert_progress_m") if isinstance(route, dict) else None
    expert = float(expert) if expert is not None else rp["length"] - proj[0]
    ratio = nuplan.progress_ratio(ego_progress, expert)
    multipliers = {"no_ego_at_fault_collisions": nuplan.at_fault_collision_score(counts),
                   "drivable_area_compliance": 0.0 if off_road else 1.0,
                   "driving_direction_compliance": direction,
                   "ego_is_making_progress": 1.0 if ratio >= nuplan.MIN_PROGRESS_RATIO else 0.0}
    weighted = {"ego_progress_along_expert_route": ratio, "time_to_collision_within_bound": ttc_ok,
                "speed_limit_compliance": speed_score, "ego_is_comfortable": 1.0 if comfortable else 0.0}
    return {"score": nuplan.combine(multipliers, weighted), "multipliers": multipliers,
            "weighted": weighted, "weights": dict(nuplan.WEIGHTS), "collisions": collisions,
            "at_fault_collisions": {k: counts.get(k, 0) for k in ("vru", "vehicle", "object")},
            "min_ttc_s": min_ttc, "ttc_available": have_ttc, "ego_progress_m": ego_progress,
            "expert_progress_m": expert, "max_overspeed_mps": max_over,
            "max_wrong_way_m_per_1s": worst, "comfort": comfort}


def score_drive(trajectory, route, events=(), speed_limits=None):
    """Both scores of one drive (module docstring). Returns {"driving_score",
    "route_completion", "route_completion_raw", "infraction_penalty", "infractions": [{"t",
    "kind", "other", "penalty", "counted", ("percentage" | "distance_m")}], "route_length_m",
    "route_progress_m", "off_route_m", "off_route_percentage", "route_finished",
    "route_ended_at", "route_max_offset_m", "nuplan_score": {"score", "multipliers", "weighted", "weights",
    "collisions", "at_fault_collisions", "min_ttc_s", "ttc_available", "ego_progress_m",
    "expert_progress_m", "max_overspeed_mps", "max_wrong_way_m_per_1s", "comfort"}}.
    ValueError for malformed inputs."""
    samples = _samples(trajectory)
    times = [s["t"] for s in samples]
    evs = _events(events)
    result, rp = _carla(samples, times, route, evs)
    result["nuplan_score"] = _nuplan(samples, times, route, evs, rp, speed_limits)
    return result


def main(argv=None):
    p = argparse.ArgumentParser(prog="python3 -m convoy_bench.score",
                                description="Scores a city_traffic run folder (docs/scoring.md).")
    p.add_argument("run_dir", help="the run folder (tracks.jsonl, summary.json)")
    p.add_argument("--route", help="route CSV with x,y columns (default: the run's ego route, "
                                   "else experiments/city_traffic/ego_route.csv)")
    args = p.parse_args(argv)
    from .runs import score_run
    try:
        result = score_run(args.run_dir, route_csv=args.route)
    except (OSError, ValueError) as e:
        print("error: %s: %s" % (args.run_dir, e), file=sys.stderr)
        return 2
    print(json.dumps(result, indent=1, default=_json_default))
    return 0


def _json_default(v):
    if isinstance(v, (np.floating, np.integer)):
        return v.item()
    raise TypeError("not JSON serialisable: %r" % (v,))


if __name__ == "__main__":
    sys.exit(main())
