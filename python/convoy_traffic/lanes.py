"""The lanes beside the ego's route, for the planner's lane changes (convoy_traffic.lane_change).

RouteLanes holds, for each point of a route_path.RoutePath, the lateral offsets (m, positive to
the route's left) of the neighbour lanes a car on the route may change into there: driving lanes
of the same direction whose road mark may be crossed (OpenDRIVE's lane_info change_left /
change_right; none inside junctions), and the speed limit there. `from_map` reads them from an OpenDRIVE map
(convoy_scenario.roads.RoadMap); tests build them directly. `map_path` finds the map of a run:
$CONVOY_EGO_MAP, else the scenario engine's Map in the run folder's scenario_config.json (what
`convoy run --scenario` writes).
"""
import bisect
import json
import math
import os

SIDES = ("left", "right")   # the order lanes are tried in: overtaking on the left first
SAME_LANE_M = 0.5           # offsets this close are the same lane


class RouteLanes:
    def __init__(self, route, sides, limits=None):
        """sides: one dict {"left": offset or None, "right": offset or None} per route point;
        limits: the speed limit (m/s or None: unknown) per route point."""
        if len(sides) != len(route.points) or (limits is not None and len(limits) != len(sides)):
            raise ValueError("RouteLanes: %d entries for %d route points" % (len(sides), len(route.points)))
        self.route = route
        self._sides = sides
        self._limits = limits or [None] * len(sides)

    def speed_limit(self, s):
        """The speed limit at s (m/s), None when the map gives none."""
        return self._limits[self._index(s)]

    def _index(self, s):
        i = bisect.bisect_right(self.route.s, s) - 1
        return min(max(i, 0), len(self.route.s) - 1)

    def sides(self, s):
        """[(side, offset)] of the lanes beside the route at s, in SIDES order."""
        entry = self._sides[self._index(s)]
        return [(k, entry[k]) for k in SIDES if entry.get(k) is not None]

    def available(self, d, s_a, s_b):
        """True when a lane at offset d is beside the route at every point from s_a to s_b."""
        i, j = self._index(s_a), self._index(s_b)
        if s_b > self.route.length:
            return False
        for entry in self._sides[i:j + 1]:
            if not any(v is not None and abs(v - d) < SAME_LANE_M for v in entry.values()):
                return False
        return True

    @classmethod
    def from_map(cls, route, roadmap, xodr=None):
        """The neighbour lanes of each route point on `roadmap` (a RoadMap); with the map's file
        `xodr` also its speed limits (convoy_bench.road_map)."""
        limits = None
        if xodr:
            from convoy_bench import road_map
            m = road_map.load(xodr)
            xs, ys = [x for x, _ in route.points], [y for _, y in route.points]
            hs = [route.heading(s) for s in route.s]
            limits = [w["speed_limit"] for w in road_map.locate(m, xs, ys, hs)]
        sides = []
        for i, (x, y) in enumerate(route.points):
            h = route.heading(route.s[i])
            loc = roadmap.locate(x, y, h, 1.0, "driving")
            entry = {"left": None, "right": None}
            if loc is not None and loc["junction"] == "-1":
                info = roadmap.lane_info(loc["road"], loc["lane"], loc["s"])
                for side in SIDES:
                    nb = info.get(side)
                    if nb is None or not info.get("change_" + side):
                        continue
                    nbi = roadmap.lane_info(loc["road"], nb, loc["s"])
                    if nbi["type"] != "driving" or nbi["forward"] != info["forward"]:
                        continue
                    px, py = roadmap.lane_pose(loc["road"], nb, loc["s"])[:2]
                    entry[side] = -math.sin(h) * (px - x) + math.cos(h) * (py - y)
            sides.append(entry)
        return cls(route, sides, limits)


def map_path(run_dir=None):
    """The OpenDRIVE map of this run, or None (module docstring)."""
    env = os.environ.get("CONVOY_EGO_MAP")
    if env:
        return env
    run_dir = run_dir or os.environ.get("CONVOY_RUN_DIR")
    if not run_dir:
        return None
    try:
        with open(os.path.join(run_dir, "scenario_config.json")) as f:
            cfg = json.load(f)
    except (OSError, ValueError):
        return None
    for e in cfg.get("EngineConfigs", []):
        if e.get("EngineType") == "scenario" and e.get("Map"):
            return e["Map"]
    return None
