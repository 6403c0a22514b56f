"""Live driving score (docs/scoring.md, "Live scoring"): accumulates, step by step, what
score.score_drive needs from the datapacks of a run, and scores the drive so far.

A pure function of its inputs, in order: `LiveScore.add(t, ego, others, collisions, signals)`
with plain values (metrics_tf.py converts the datapacks), then `result(final)`. No clock, no
files but the map. Replaying the same inputs gives bit-identical results (`convoy score`).

Per sample, as runs.py derives them for a city_traffic run folder (the same rules):
- on_road, wrong_way (a driving lane outside a junction whose direction differs from the
  ego's heading by more than 120 deg), in_junction, multiple_lanes (box corners in different
  lanes outside junctions), speed_limit: from the map (road_map);
- ttc (nuplan.ttc_at against the other road users, leaving out those that collided with the
  ego before), traffic_speed (the mean speed of the other road users that are not pedestrians).
Events:
- collisions of the ego from the world's `collisions` list (each contact once): the other a
  pedestrian -> collision_pedestrian; car, truck, bus, cyclist -> collision_vehicle; anything
  else -> collision_static, with the other's state at that step;
- red_light: the ego's front crosses a stop line on red and enters the junction on red
  (experiments/city_traffic/recorder.py's rule), when the map has stop lines;
- scenario_timeout: the run ends (`result(final=True, timed_out=True)`) before the ego has
  finished its route.

Bounded memory and work per step (issue 30): LiveScore keeps no list of samples. Each sample
updates, as it arrives, the aggregates score.score_drive would compute from the whole
trajectory (blocked time, route progress and its off-route stretches, the minimum-speed
checkpoints, TTC, overspeed, the driving-direction sums), with exact streaming sums where
score.py uses math.fsum, so result() gives the same bits as score.score_drive over all the
samples. What depends on the whole trajectory's mean time step (nuPlan's comfort: its
Savitzky-Golay coefficients; the driving-direction horizon; the speed-limit score) keeps
8-byte floats per sample (time, speed, yaw, direction progress: 32 bytes a sample, 2.3 MB an
hour at 20 Hz); the ego states that collision events refer to come from a window of the last
STATE_WINDOW samples (a collision reported later than that after its time: see _resolve).
"""

import bisect
import collections
import math
from array import array

import numpy as np

from . import geometry, nuplan, road_map, score
from .exact_sum import ExactSum as _ExactSum
from .runs import EGO_WIDTH, VEHICLE_CLASSES, WRONG_WAY_ANGLE

STATE_WINDOW = 1200   # samples (60 s at 20 Hz) of ego states kept for the collision events
_STATE_KEYS = ("t", "x", "y", "yaw", "speed", "length", "width", "length_offset", "multiple_lanes",
               "on_road")


class LiveScore:
    def __init__(self, route_points, map_path, stop_lines=(), ego="smart_car", ego_width=EGO_WIDTH):
        self.route = {"points": [[float(p[0]), float(p[1])] for p in route_points]}
        self.map = road_map.load(map_path)
        self.stop_lines = list(stop_lines)
        self.ego = ego
        self.ego_width = ego_width
        self.events = []
        self.collided = {}         # other -> time of its first collision with the ego
        self.seen_collisions = 0
        self.prev_ahead = {}
        self.crossed_on_red = {}
        self.last_t = None
        # the aggregates of the samples so far (score.score_drive's terms)
        self.n = 0                 # samples
        self._bad = None           # score._samples' error for the first malformed sample
        self._route_error = None
        self._pts = self._cum = None
        self._L = None
        if len(self.route["points"]) >= 2:
            try:
                self._pts, self._cum = geometry.route_polyline(self.route)
                self._L = float(self._cum[-1])
            except ValueError as e:
                self._route_error = str(e)
        # ego states for the collision events (score._state_at)
        self._first_state = None
        self._window = collections.deque(maxlen=STATE_WINDOW)
        self._event_state = []     # per self.events entry: its ego state, None (pending or not a collision)
        self._pending = []         # indices into self.events of collisions whose state is not known yet
        self.unresolved_states = 0  # collisions reported after their sample left the window
        # score.blocked_time
        self._blocked_start = None
        self._blocked_t = None
        # score.route_progress
        self._proj0 = self._proj_last = None
        self._s_max = 0.0
        self._finished = False
        self._max_offset = 0.0
        self._off = _ExactSum()
        self._stretches = []       # [{"t", "kind", "sum": _ExactSum, "_last"}]
        # score._carla's running progress and score.min_speed_events
        self._running = 0.0
        self._ms_current = 0.0
        self._ms_mean = 0.0
        self._ms_ego = 0.0
        self._ms_points = 0
        self._ms_events = []
        self._has_traffic = False
        # score._nuplan
        self._have_ttc = False
        self._ttc_min = None
        self._ttc_all_ok = True
        self._off_road = False
        self._over = _ExactSum()
        self._max_over = None
        self._t = array("d")       # the whole trajectory's mean time step needs every time
        self._speed = array("d")   # nuplan.comfort: its coefficients depend on that step
        self._yaw = array("d")
        self._prog = array("d")    # nuplan.driving_direction_compliance's per-sample movement
        self._dir_min = {}         # horizon -> [samples summed, min of the window sums]
        self._prev_xy = None

    def _flags(self, s):
        corners = geometry.box_corners([s["x"]], [s["y"]], [s["yaw"]], [s["length"]], self.ego_width,
                                       [s["length_offset"]])
        xs = [s["x"]] + [float(corners[0, k, 0]) for k in range(4)]
        ys = [s["y"]] + [float(corners[0, k, 1]) for k in range(4)]
        where, *cw = road_map.locate(self.map, xs, ys, [s["yaw"]] * 5)
        lanes = {(c["road"], c["lane"]) for c in cw}
        in_junction = where["junction"] or any(c["junction"] for c in cw)
        wrong = (where["lane_type"] == "driving" and not where["junction"] and where["heading"] is not None
                 and math.cos(where["heading"] - s["yaw"]) < math.cos(WRONG_WAY_ANGLE))
        s.update({"road": where["road"], "lane": where["lane"], "on_road": where["on_road"],
                  "wrong_way": wrong, "in_junction": in_junction,
                  "multiple_lanes": len(lanes) > 1 and not in_junction,
                  "speed_limit": where["speed_limit"]})

    def _red_lights(self, t, s, signals):
        fx = s["x"] + (s["length_offset"] + 0.5 * s["length"]) * math.cos(s["yaw"])
        fy = s["y"] + (s["length_offset"] + 0.5 * s["length"]) * math.sin(s["yaw"])
        for sl in self.stop_lines:
            a = sl.ahead(fx, fy, s["yaw"], at_entry=True)
            prev = self.prev_ahead.get(sl.id)
            if a is None:
                self.prev_ahead.pop(sl.id, None)
                continue
            self.prev_ahead[sl.id] = a
            b = sl.ahead(fx, fy, s["yaw"])
            pb = self.prev_ahead.get((sl.id, "line"))
            self.prev_ahead[(sl.id, "line")] = b
            if pb is not None and b is not None and pb > 0 >= b:
                self.crossed_on_red[sl.id] = signals.get(sl.id) == "red"
            if prev is not None and prev > 0 >= a and signals.get(sl.id) == "red" and \
                    self.crossed_on_red.get(sl.id, True):
                self._event({"t": t, "kind": "red_light", "other": sl.id})

    def _event(self, e):
        self.events.append(e)
        self._event_state.append(None)
        if e["kind"] in score.COLLISION_KINDS:
            self._pending.append(len(self.events) - 1)

    def add(self, t, ego, others, collisions=(), signals=None):
        """One step: ego {"x", "y", "yaw", "speed", "length", "length_offset"}; others {id:
        {"class", "x", "y", "yaw", "speed", "length", "length_offset"}}; collisions the world's
        cumulative list; signals {id: state}."""
        t = float(t)
        if self.last_t is not None and t <= self.last_t:
            return
        self.last_t = t
        s = {"t": t, "x": float(ego["x"]), "y": float(ego["y"]), "yaw": float(ego["yaw"]),
             "speed": float(ego["speed"]), "length": float(ego.get("length") or 2.5),
             "width": self.ego_width, "length_offset": float(ego.get("length_offset") or 0.0)}
        self._flags(s)
        for c in list(collisions)[self.seen_collisions:]:
            a, b = c.get("a"), c.get("b")
            if self.ego not in (a, b) or a == b:
                continue
            other, cls = (b, c.get("class_b")) if a == self.ego else (a, c.get("class_a"))
            kind = ("collision_pedestrian" if cls == "pedestrian" else
                    "collision_vehicle" if cls in VEHICLE_CLASSES else "collision_static")
            e = {"t": float(c["t"]), "kind": kind, "other": other, "other_class": cls}
            if other in others:
                e["other_state"] = dict(others[other])
            self._event(e)
            self.collided.setdefault(other, float(c["t"]))
        self.seen_collisions = len(list(collisions))
        if signals:
            self._red_lights(t, s, signals)
        active = [o for oid, o in sorted(others.items())
                  if not (oid in self.collided and self.collided[oid] < t)]
        wide = s["multiple_lanes"] or s["in_junction"] or not s["on_road"]
        s["ttc"] = nuplan.ttc_at(s, active, wide=wide)
        vehicles = [o["speed"] for _, o in sorted(others.items()) if o["class"] in VEHICLE_CLASSES]
        s["traffic_speed"] = math.fsum(vehicles) / len(vehicles) if vehicles else None
        self._sample(s)

    # --- the aggregates, one sample at a time (score.py's definitions, in its order) ----------

    def _sample(self, s):
        i = self.n
        self.n += 1
        if self._bad is not None:
            return
        for k in ("t", "x", "y", "yaw", "speed"):              # score._samples
            if not math.isfinite(s[k]):
                self._bad = "trajectory sample %d: %s is not finite" % (i, k)
                return
        t, x, y, speed = s["t"], s["x"], s["y"], s["speed"]
        state = {k: s.get(k) for k in _STATE_KEYS}
        if i == 0:
            self._first_state = state
        self._window.append(state)
        if self._pending:
            self._resolve(t)
        # score.blocked_time: the first time found stays
        if self._blocked_t is None:
            if speed < score.BLOCKED_SPEED:
                self._blocked_start = t if self._blocked_start is None else self._blocked_start
                if t - self._blocked_start >= score.BLOCKED_TIME_S:
                    self._blocked_t = t
            else:
                self._blocked_start = None
        if self._pts is not None:
            self._sample_route(i, s, t, x, y, speed, self._blocked_t)
        if s.get("traffic_speed") is not None:
            self._has_traffic = True
        self._sample_nuplan(i, s, t, x, y, speed)

    def _sample_route(self, i, s, t, x, y, speed, end_t):
        """score.route_progress, score._carla's running progress, score.min_speed_events."""
        if i == 0:
            p, dist, _ = geometry.project_on_polyline(self._pts, self._cum, x, y)
            self._proj0 = p
        else:
            p, dist, _ = geometry.project_on_polyline(self._pts, self._cum, x, y,
                                                      self._s_max - score.PROJECTION_BACK_M,
                                                      self._s_max + score.PROJECTION_AHEAD_M)
        self._proj_last = p
        if end_t is None or t <= end_t:
            self._max_offset = max(self._max_offset, dist)
        if not ((end_t is not None and t > end_t) or dist > score.ROUTE_DEVIATION_M):
            gain = max(0.0, p - self._s_max) if i else p
            self._s_max = max(self._s_max, p)
            kind = score._outside_kind(s) if i else None
            if kind is not None:
                self._off.add(gain)
                st = self._stretches[-1] if self._stretches else None
                if st is not None and st["kind"] == kind and st["_last"] == i - 1:
                    st["sum"].add(gain)
                    st["_last"] = i
                else:
                    st = {"t": t, "kind": kind, "sum": _ExactSum(), "_last": i}
                    st["sum"].add(gain)
                    self._stretches.append(st)
            end_x, end_y = self._pts[-1]
            if 100.0 * self._s_max / self._L > score.FINISH_PERCENT and \
                    math.hypot(x - end_x, y - end_y) < score.FINISH_DISTANCE_M:
                self._finished = True
        # score._carla's running progress, score.min_speed_events
        if end_t is None or t <= end_t:
            self._running = max(self._running, p)
        if self._running - self._ms_current > self._L / score.MIN_SPEED_CHECKPOINTS:
            ev = self._min_speed_close(t)
            if ev is not None:
                self._ms_events.append(ev)
            self._ms_current, self._ms_mean, self._ms_ego, self._ms_points = self._running, 0.0, 0.0, 0
        ts = s.get("traffic_speed")
        if ts is not None:
            self._ms_mean += float(ts)
            self._ms_ego += speed
            self._ms_points += 1

    def _sample_nuplan(self, i, s, t, x, y, speed):
        """score._nuplan's inputs: TTC, overspeed, off road, and the per-sample arrays."""
        if "ttc" in s:
            self._have_ttc = True
        v = s.get("ttc")
        if v is not None and math.isfinite(float(v)):
            v = float(v)
            if self._ttc_min is None or v < self._ttc_min:
                self._ttc_min = v
            if not v > nuplan.LEAST_MIN_TTC:
                self._ttc_all_ok = False
        lim = s.get("speed_limit")
        over = max(0.0, float(speed) - float(lim)) if lim is not None else 0.0
        self._over.add(over)
        if self._max_over is None or over > self._max_over:
            self._max_over = over
        if s.get("on_road") is False:
            self._off_road = True
        if i == 0:
            self._prog.append(0.0)
        else:
            px, py = self._prev_xy
            d = math.hypot(x - px, y - py)
            self._prog.append(-d if s.get("wrong_way") is True else d)
        self._prev_xy = (x, y)
        self._t.append(t)
        self._speed.append(speed)
        self._yaw.append(s["yaw"])

    def _min_speed_close(self, t):
        """score.min_speed_events' close()."""
        if self._ms_points > 0 and self._ms_mean:
            pct = round(self._ms_ego / self._ms_points / (self._ms_mean / self._ms_points) * 100.0, 2)
        else:
            pct = 100.0
        if pct < 100.0:
            return {"t": t, "kind": "min_speed", "other": None, "percentage": pct}
        return None

    def _resolve(self, newest_t):
        """score._state_at for the pending collisions: the last sample at or before the
        event's time (the first sample before the trajectory starts), known for good once a
        sample after it has come. A collision reported when its sample has left the window
        takes the window's oldest state (counted in unresolved_states)."""
        still = []
        times = None
        for idx in self._pending:
            te = self.events[idx]["t"]
            if not newest_t > te:
                still.append(idx)
                continue
            if times is None:
                times = [w["t"] for w in self._window]
            k = bisect.bisect_right(times, te) - 1
            if k >= 0:
                st = self._window[k]
            elif te < self._first_state["t"]:
                st = self._first_state
            else:
                st = self._window[0]
                self.unresolved_states += 1
            self._event_state[idx] = st
        self._pending = still

    def _state_of(self, idx):
        st = self._event_state[idx] if idx < len(self._event_state) else None
        if st is None:              # no sample after the event yet: the last one
            st = self._window[-1]
        return st

    # --- the result ---------------------------------------------------------------------------

    def result(self, final=False, timed_out=False):
        """score.score_drive's result for the drive so far (None with fewer than 2 samples).
        final and timed_out: the run ended before the ego finished its route -> one
        scenario_timeout infraction (at the last sample's time)."""
        if self.n < 2 or len(self.route["points"]) < 2:
            return None
        if self._bad is not None:
            raise ValueError(self._bad)
        if self._route_error is not None:
            raise ValueError(self._route_error)
        events = list(self.events)
        if final and timed_out and not self._finished:
            events.append({"t": self._t[-1], "kind": "scenario_timeout", "other": None})
        evs = score._events(events)
        for idx, e in enumerate(evs):
            if e["kind"] in score.COLLISION_KINDS:
                e["_ego"] = self._state_of(idx)
        tt = np.array(self._t, float)
        dt = float(np.mean(np.diff(tt)))
        result = self._carla(evs)
        result["nuplan_score"] = self._nuplan(evs, tt, dt)
        return result

    def _carla(self, events):
        blocked = [e["t"] for e in events if e["kind"] == "agent_blocked"]
        computed = []
        tb = self._blocked_t
        if tb is not None:
            computed.append({"t": tb, "kind": "agent_blocked", "other": None})
            blocked.append(tb)
        end_t = min(blocked) if blocked else None
        if end_t != tb:
            raise ValueError("LiveScore: agent_blocked events are computed, not given")
        L = self._L
        if self._has_traffic:
            computed += self._ms_events
            if self._running / L > score.MIN_SPEED_END_FRACTION:
                ev = self._min_speed_close(self._t[-1])
                if ev is not None:
                    computed.append(ev)
        stretches = [{"t": st["t"], "kind": st["kind"], "distance_m": st["sum"].value()}
                     for st in self._stretches if st["sum"].value() > 0.0]
        for st in stretches:
            computed.append({"t": st["t"], "kind": st["kind"], "other": None, "distance_m": st["distance_m"],
                             "_from_flags": True})
        all_events = sorted(events + [dict(e) for e in computed], key=score._event_key)
        s = self._s_max
        d_off = self._off.value() + math.fsum(float(e.get("distance_m") or 0.0) for e in all_events
                                              if e["kind"] in score.ROUTE_KINDS and not e.get("_from_flags"))
        d_off = min(d_off, s)
        rc_raw = 100.0 if self._finished else 100.0 * s / L
        rc = rc_raw * (1.0 - d_off / s) if s > 0.0 else rc_raw
        penalty, infractions = 1.0, []
        for e in all_events:
            counted = True
            if e["kind"] in score.COLLISION_KINDS:
                v = e.get("ego_speed")
                v = e["_ego"]["speed"] if v is None else float(v)
                counted = v >= score.CARLA_STOPPED_SPEED
            f = score.infraction_factor(e) if counted else 1.0
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
                "route_finished": self._finished, "route_ended_at": end_t,
                "route_max_offset_m": self._max_offset}

    def _nuplan(self, events, tt, dt):
        collisions, seen, counts, any_fault = [], set(), {}, False
        for e in sorted((e for e in events if e["kind"] in score.COLLISION_KINDS), key=score._event_key):
            if e["other"] is not None:
                if e["other"] in seen:
                    continue
                seen.add(e["other"])
            ego = e["_ego"]
            ctype = e.get("collision_type") or nuplan.collision_type(
                ego, e.get("other_state"), static=e["kind"] == "collision_static")
            wide = bool(ego.get("multiple_lanes")) or ego.get("on_road") is False
            at_fault = nuplan.is_at_fault(ctype, wide)
            other_class = e.get("other_class") or (e.get("other_state") or {}).get("class")
            category = nuplan.collision_category(e["kind"], other_class)
            if at_fault:
                counts[category] = counts.get(category, 0) + 1
                any_fault = True
            collisions.append({"t": e["t"], "kind": e["kind"], "other": e["other"], "category": category,
                               "type": ctype, "at_fault": at_fault})
        # an at-fault collision's sample has TTC 0 (every TTC is > 0 otherwise)
        min_ttc = 0.0 if any_fault else self._ttc_min
        ttc_ok = 0.0 if any_fault else (1.0 if self._ttc_all_ok else 0.0)
        # nuplan.speed_limit_compliance
        duration = float(tt[-1] - tt[0])
        if duration <= 0.0:
            speed_score, max_over = 1.0, 0.0
        else:
            loss = self._over.value() * dt / (max(nuplan.SPEED_LIMIT_MAX_OVERSPEED, 1e-3) * duration)
            speed_score, max_over = max(0.0, 1.0 - loss), self._max_over
        comfort, comfortable = nuplan.comfort(tt, np.array(self._speed, float), np.array(self._yaw, float))
        direction, worst = self._direction(dt, [e.get("distance_m") or 0.0 for e in events
                                                if e["kind"] == "wrong_way"])
        off_road = self._off_road or any(e["kind"] == "off_road" for e in events)
        ego_progress = self._proj_last - self._proj0
        expert = self._L - self._proj0
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
                "min_ttc_s": min_ttc, "ttc_available": self._have_ttc, "ego_progress_m": ego_progress,
                "expert_progress_m": expert, "max_overspeed_mps": max_over,
                "max_wrong_way_m_per_1s": worst, "comfort": comfort}

    def _direction(self, dt, extra_m):
        """nuplan.driving_direction_compliance: the min of the window sums per horizon kept
        and extended by the new samples (a horizon seen first sums the whole trajectory once)."""
        n = self.n
        horizon = int(nuplan.DIRECTION_HORIZON_S / dt) if n > 1 else 0
        done, low = self._dir_min.get(horizon, (0, None))
        prog = self._prog
        for i in range(done, n):
            v = math.fsum(prog[max(0, i - horizon):i + 1])
            if low is None or v < low:
                low = v
        if horizon not in self._dir_min and len(self._dir_min) >= 8:
            self._dir_min.pop(next(iter(self._dir_min)))
        self._dir_min[horizon] = (n, low)
        worst = max([max(0.0, -low)] + [float(e) for e in extra_m])
        if worst < nuplan.DIRECTION_COMPLIANCE_M:
            return 1.0, worst
        return (0.5 if worst < nuplan.DIRECTION_VIOLATION_M else 0.0), worst


def summary_fields(r, final):
    """The summary.json fields of a score result."""
    return {
        "driving_score": r["driving_score"],
        "route_completion": r["route_completion"],
        "infraction_penalty": r["infraction_penalty"],
        "infractions": [{"time": i["t"], "kind": i["kind"], "other": i.get("other"),
                         "penalty": i.get("penalty"), "counted": i.get("counted", True),
                         **({"percentage": i["percentage"]} if "percentage" in i else {}),
                         **({"distance_m": i["distance_m"]} if "distance_m" in i else {})}
                        for i in r["infractions"]],
        "nuplan_score": r["nuplan_score"]["score"],
        "score": {k: v for k, v in r.items() if k not in ("infractions",)},
        "score_final": bool(final),
    }
