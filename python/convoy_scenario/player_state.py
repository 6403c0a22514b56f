"""The state of an entity the scenario engine moves itself (the default controller: exact
scenario control, docs/scenarios.md "The player"), and moving it along its lane.

An entity is either on a lane, (road, lane, s, offset): offset lateral from the lane's centre,
positive to the left of the road's reference direction (OpenDRIVE t), its heading the lane's
driving direction plus `h_rel`; or free, (x, y, z, h), when no lane is under it. Moving along
its lane keeps the offset and continues into the lane that follows at the end of a lane
section: the one on its route when it has one, else the one whose direction changes least
(esmini picks at random; docs/scenarios.md says why Convoy does not). At the end of a road
with no lane after it, the entity stops there and `end_of_road` is set."""

import math

TWO_PI = 2.0 * math.pi
PROBE_DS = 0.5      # m: probe for the distance per unit s at an offset
PROBE_MARGIN = 1e-4  # m: probes stay this far inside a lane section
END_EPS = 1e-6
ENTRY_NUDGE = 1e-6  # m
# lane types a vehicle may drive on (OffroadCondition: off these)
ROAD_TYPES = ("driving", "entry", "exit", "onRamp", "offRamp", "connectingRamp", "bidirectional",
              "stop", "parking", "shoulder", "bus", "taxi", "HOV", "restricted", "biking")


def wrap(a):
    """a in [0, 2 pi)."""
    a = math.fmod(a, TWO_PI)
    return a + TWO_PI if a < 0 else a


def angle_diff(a, b):
    return math.atan2(math.sin(a - b), math.cos(a - b))


class NoRoads:
    """The road map of a scenario without one (no RoadNetwork LogicFile): every entity is free
    (world coordinates); anything that needs a lane is an error naming what."""

    def locate(self, x, y, heading=None, max_distance=5.0, lane_types=None):
        return None

    def _none(self, *args, **kwargs):
        from .xmltree import ScenarioError
        raise ScenarioError("the scenario has no road network (RoadNetwork LogicFile): a lane or "
                            "road position cannot be placed")

    lane_pose = road_pose = lane_info = lanes_at = next_lanes = prev_lanes = route = _none


class EntityState:
    def __init__(self, name, length, width, length_offset):
        self.name = name
        self.length, self.width, self.length_offset = length, width, length_offset
        self.road = None          # None: free (no lane)
        self.lane = 0
        self.s = 0.0
        self.offset = 0.0
        self.h_rel = 0.0
        self.x = self.y = self.z = 0.0
        self.h = 0.0
        self.pitch = 0.0
        self.speed = 0.0
        self.vx = self.vy = 0.0
        self.ax = self.ay = 0.0
        self.road_t = 0.0
        self.offroad = False
        self.odometer = 0.0
        self.end_of_road = False
        self.collisions = []      # entities whose boxes overlap this one's (after a step)
        self.placed = False       # a position was ever given
        self.route = None         # a RoutePath (player_routes.py): its lanes win at forks

    def as_world(self):
        """The storyboard's state dict (docs/scenarios.md, Execution)."""
        d = {"x": self.x, "y": self.y, "z": self.z, "yaw": self.h, "speed": self.speed,
             "vx": self.vx, "vy": self.vy, "ax": self.ax, "ay": self.ay,
             "length": self.length, "width": self.width, "length_offset": self.length_offset,
             "odometer": self.odometer, "end_of_road": self.end_of_road,
             "collisions": list(self.collisions),
             "offroad": self.road is None or self.offroad}
        if self.road is not None:
            d.update(road=self.road, lane=self.lane, s=self.s, t=self.road_t)
        return d


class LaneMover:
    """Positions on lanes through a RoadMap (convoy_scenario.roads)."""

    def __init__(self, roads):
        self.roads = roads

    def place_lane(self, st, road, lane, s, offset=0.0, h_rel=0.0):
        st.road, st.lane, st.s, st.offset, st.h_rel = str(road), int(lane), float(s), float(offset), h_rel
        st.placed = True
        self.update_pose(st)

    def place_world(self, st, x, y, z=None, h=None, snap=True):
        """At a world point; on the lane under it (heading h relative to the lane) when there is
        one, else free."""
        loc = self.roads.locate(x, y, heading=h, max_distance=0.0) if snap else None
        st.placed = True
        if loc is not None and loc.get("distance", 0.0) <= END_EPS:
            lane_h = loc["heading"]
            st.road, st.lane, st.s = str(loc["road"]), int(loc["lane"]), float(loc["s"])
            st.offset = float(loc["t"])
            st.h_rel = 0.0 if h is None else angle_diff(h, lane_h)
            self.update_pose(st)
            return
        st.road = None
        st.x, st.y = float(x), float(y)
        st.z = 0.0 if z is None else float(z)
        st.h = wrap(0.0 if h is None else h)

    def update_pose(self, st):
        if st.road is None:
            return
        x, y, z, heading, pitch = self.roads.lane_pose(st.road, st.lane, st.s, st.offset)
        st.x, st.y, st.z = x, y, z
        info = self.roads.lane_info(st.road, st.lane, st.s)
        st.road_t = info["centre_t"] + st.offset
        st.h = wrap(heading + st.h_rel)
        st.pitch = pitch
        st.offroad = not self._on_road_surface(st, info)

    def _on_road_surface(self, st, own):
        """Whether the entity's reference point is on a lane of a road type (its own lane when
        its offset keeps it there, else the lane of its road at its t): an OffroadCondition
        holds while it is not (a LaneOffset beyond the road's edge)."""
        if abs(st.offset) <= own["width"] / 2.0 + 1e-9:
            return own["type"] in ROAD_TYPES
        for lane in self.roads.lanes_at(st.road, st.s):
            info = self.roads.lane_info(st.road, lane, st.s)
            if abs(st.road_t - info["centre_t"]) <= info["width"] / 2.0 + 1e-9:
                return info["type"] in ROAD_TYPES
        return False

    def lane_forward(self, st):
        return self.roads.lane_info(st.road, st.lane, st.s)["forward"]

    def s_per_metre(self, st, forward):
        """ds per metre travelled at the entity's offset (curvature makes the two differ)."""
        d = PROBE_DS if forward else -PROBE_DS
        info = self.roads.lane_info(st.road, st.lane, st.s)
        # probes strictly inside the section (its boundary s belongs to the next section)
        lo, hi = info["s0"] + PROBE_MARGIN, info["s1"] - PROBE_MARGIN
        s1 = min(max(st.s, lo), hi)
        s2 = min(max(s1 + d, lo), hi)
        if abs(s2 - s1) < 1e-3:
            s2 = min(max(s1 - d, lo), hi)
        if abs(s2 - s1) < 1e-3:
            return 1.0
        a = self.roads.lane_pose(st.road, st.lane, s1, st.offset)
        b = self.roads.lane_pose(st.road, st.lane, s2, st.offset)
        dist = math.hypot(b[0] - a[0], b[1] - a[1])
        return abs(s2 - s1) / dist if dist > 1e-9 else 1.0

    def choose_next(self, st, options):
        if st.route is not None:
            ranked = sorted(options, key=lambda o: st.route.prefers(o["road"], o["lane"]))
            if st.route.prefers(ranked[0]["road"], ranked[0]["lane"]) < 2:
                best = st.route.prefers(ranked[0]["road"], ranked[0]["lane"])
                options = [o for o in ranked if st.route.prefers(o["road"], o["lane"]) == best]
                if len(options) == 1:
                    return options[0]
        here = self.roads.lane_pose(st.road, st.lane, st.s, 0.0)[3]
        best, best_turn = None, None
        for o in options:
            info = self.roads.lane_info(o["road"], o["lane"], o["s"])
            probe = o["s"] + (2.0 if o["forward"] else -2.0)
            probe = min(max(probe, info["s0"]), info["s1"])
            h = self.roads.lane_pose(o["road"], o["lane"], probe, 0.0)[3]
            turn = abs(angle_diff(h, here))
            if best is None or turn < best_turn - 1e-9:
                best, best_turn = o, turn
        return best

    def move_along(self, st, distance):
        """Moves the entity `distance` m along its lane, keeping its offset: the way it faces
        (its lane's driving direction, or against it when |h_rel| > 90 degrees), backwards for
        a negative distance. Returns the distance not made (at a road's end)."""
        if st.road is None:
            st.x += distance * math.cos(st.h)
            st.y += distance * math.sin(st.h)
            return 0.0
        # along the lane's driving direction, or against it
        along = (math.cos(st.h_rel) >= 0) != (distance < 0)
        left = abs(distance)
        st.end_of_road = False
        for _ in range(64):
            if left <= END_EPS:
                break
            info = self.roads.lane_info(st.road, st.lane, st.s)
            plus_s = info["forward"] == along
            k = self.s_per_metre(st, plus_s)
            edge = info["s1"] if plus_s else info["s0"]
            room = abs(edge - st.s) / k
            if left < room - END_EPS:   # landing on the edge crosses it (into the next lane)
                st.s += (1 if plus_s else -1) * left * k
                left = 0.0
                break
            left -= room
            # just inside this section (a boundary s belongs to the next section)
            st.s = edge - ENTRY_NUDGE if plus_s else edge + ENTRY_NUDGE
            options = (self.roads.next_lanes if along else self.roads.prev_lanes)(st.road, st.lane, st.s)
            nxt = self.choose_next(st, options) if options else None
            if nxt is None:   # the lane ends here: the entity stays at its end
                st.end_of_road = True
                break
            st.road, st.lane = str(nxt["road"]), int(nxt["lane"])
            # just inside the lane entered (a section's boundary belongs to both sections)
            inward = 1.0 if nxt["forward"] == along else -1.0
            st.s = float(nxt["s"]) + inward * ENTRY_NUDGE
        self.update_pose(st)
        return math.copysign(left, distance)
