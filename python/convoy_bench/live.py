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
"""

import math

from . import geometry, nuplan, road_map, score
from .runs import EGO_WIDTH, VEHICLE_CLASSES, WRONG_WAY_ANGLE


class LiveScore:
    def __init__(self, route_points, map_path, stop_lines=(), ego="smart_car", ego_width=EGO_WIDTH):
        self.route = {"points": [[float(p[0]), float(p[1])] for p in route_points]}
        self.map = road_map.load(map_path)
        self.stop_lines = list(stop_lines)
        self.ego = ego
        self.ego_width = ego_width
        self.samples = []
        self.events = []
        self.collided = {}         # other -> time of its first collision with the ego
        self.seen_collisions = 0
        self.prev_ahead = {}
        self.crossed_on_red = {}
        self.last_t = None

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
                self.events.append({"t": t, "kind": "red_light", "other": sl.id})

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
            self.events.append(e)
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
        self.samples.append(s)

    def result(self, final=False, timed_out=False):
        """score.score_drive's result for the drive so far (None with fewer than 2 samples).
        final and timed_out: the run ended before the ego finished its route -> one
        scenario_timeout infraction (at the last sample's time)."""
        if len(self.samples) < 2 or len(self.route["points"]) < 2:
            return None
        events = list(self.events)
        r = score.score_drive(self.samples, self.route, events)
        if final and timed_out and not r["route_finished"]:
            events.append({"t": self.samples[-1]["t"], "kind": "scenario_timeout", "other": None})
            r = score.score_drive(self.samples, self.route, events)
        return r


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
