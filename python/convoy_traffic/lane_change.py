"""The ego planner's lane changes (issue 27, item 4: "it passes a stopped vehicle by a lane change
when the adjacent lane is free (MOBIL-style safety check)").

The ego keeps to its route's lane; it leaves it for a neighbour lane of the same direction
(convoy_traffic.lanes.RouteLanes: left preferred, then right) when
- incentive: its leader there is a vehicle (car, truck, bus) slower than SlowLeader x the cruise
  speed for at least PassAfter s (a broken-down or parked car, not one braking in traffic), and
  MOBIL's criterion holds: a_new - a_cur + p (followers' gains) > ChangeThreshold, with the
  IDM accelerations of the ego and its followers before and after;
- safety (MOBIL): the new follower in the target lane would brake at most SafeDeceleration
  (b_safe) behind the ego, the ego itself too behind its new leader, and the gaps ahead and
  behind are at least the IDM's standstill distance s0; nobody is beside the ego there;
- room: the manoeuvre (LaneChangeTime x speed, at least MinLaneChangeLength m) has moved the
  ego's path clear of the slow leader (half widths + LateralMargin) by the leader's rear, and
  the target lane lasts beyond the leader by one more manoeuvre.
With sensor input (Input "sensors") the cruise speed is also at most OccludedSpeed past a standing
vehicle beside the path (its side within OccludedGap m of the ego's corridor), from OccludedRange m
before its rear until the ego's front is 1 m past its front, reached at ComfortDeceleration:
the ego's sensors do not see behind it, where a walker may step out (occluded_speed). From the
moment such a leader is slow (and a lane to pass it is there) the ego keeps
LaneChangeStandoff m more room to it, so that it can still pull out once it may. Once past, it returns to the route's lane when that is safe (same check) and
not worse by more than ChangeThreshold, or when the passing lane ends.

A manoeuvre is a lateral offset from the route, d(s), along the route's arc length: a half
cosine from d0 to d1 over [s0, s1]. While the offset is not zero the planner steers (pure
pursuit to the offset route LookAhead m ahead, the follower's gain and limit); otherwise the
route follower steers. Objects come in route coordinates (s, d, v along the route).
"""
import math

# key: (default, minimum, maximum); the planner's PARAMETERS include these
LANE_PARAMETERS = {
    "LaneChange": (1.0, 0.0, 1.0),             # 1: pass stopped vehicles by a lane change
    "SafeDeceleration": (4.0, 0.5, 10.0),      # m/s^2: MOBIL's b_safe
    "ChangeThreshold": (0.2, 0.0, 5.0),        # m/s^2: MOBIL's a_thr
    "Politeness": (0.3, 0.0, 1.0),             # MOBIL's p
    "SlowLeader": (0.3, 0.0, 1.0),             # x cruise speed: a leader this slow may be passed
    "PassAfter": (6.0, 0.0, 60.0),             # s: ... once it has been that slow this long
    "LaneChangeTime": (4.0, 1.0, 10.0),        # s: a manoeuvre's duration at speed
    "MinLaneChangeLength": (12.0, 5.0, 100.0),  # m: a manoeuvre's length at low speed
    "LaneChangeStandoff": (10.0, 0.0, 50.0),   # m: more room to a leader to pass while waiting
    "LookAhead": (7.0, 2.0, 30.0),             # m: the steering's look-ahead during a manoeuvre
    "FollowFlow": (1.0, 0.0, 1.0),             # 1: cruise with the traffic's flow (up to the limit)
    "FlowRange": (60.0, 0.0, 500.0),           # m: vehicles this close ahead or beside make the flow
    "MaxCruiseSpeed": (50 / 3.6, 0.0, 60.0),   # m/s: the flow's cap where the map gives no limit
    "OccludedSpeed": (5.0, 0.0, 60.0),         # m/s, sensor input: past a standing vehicle (0: off)
    "OccludedGap": (2.0, 0.0, 10.0),           # m: ... that stands this close beside the path
    "OccludedRange": (15.0, 0.0, 100.0),       # m: ... from this far before its rear
}
VEHICLE_CLASSES = ("car", "truck", "bus")
STANDING_SPEED = 0.5  # m/s: a vehicle this slow stands (occluded_speed)
STEER_GAIN = 1.2   # as experiments/city_traffic/ego_driver.py
MAX_STEER = 0.55   # rad


def idm(p, v, v0, gap=None, v_lead=0.0, extra_s0=0.0):
    """IDM acceleration at speed v (desired v0) behind a leader `gap` m ahead at v_lead (None:
    free road), keeping extra_s0 m more than the standstill distance."""
    v0 = max(v0, 0.01)
    acc = p["MaxAcceleration"] * (1 - (max(v, 0.0) / v0) ** p["Delta"])
    if gap is not None:
        s_star = p["StandstillDistance"] + extra_s0 + max(0.0, v * p["TimeGap"] + v * (v - v_lead) / (
            2 * math.sqrt(p["MaxAcceleration"] * p["ComfortDeceleration"])))
        acc -= p["MaxAcceleration"] * (s_star / max(gap, 0.01)) ** 2
    return acc


class Manoeuvre:
    """The lateral offset d(s): d0 before s0, d1 after s1, a half cosine between."""

    def __init__(self, s0, s1, d0, d1):
        self.s0, self.s1, self.d0, self.d1 = s0, s1, d0, d1

    def offset(self, s):
        if s <= self.s0:
            return self.d0
        if s >= self.s1:
            return self.d1
        u = (s - self.s0) / (self.s1 - self.s0)
        return self.d0 + (self.d1 - self.d0) * (1 - math.cos(math.pi * u)) / 2


def lane_neighbours(objs, centre, half, s_ego, front, rear):
    """(leader, follower, beside) in the lane centred at offset `centre`: each leader / follower
    is (object, gap m) or None; beside is True when one overlaps the ego along the route."""
    lead = fol = None
    beside = False
    for o in objs:
        if abs(o["d"] - centre) >= half:
            continue
        o_front, o_rear = o["s"] + o["length"] / 2, o["s"] - o["length"] / 2
        if o_rear >= s_ego + front:
            gap = o_rear - s_ego - front
            if lead is None or gap < lead[1]:
                lead = (o, gap)
        elif o_front <= s_ego - rear:
            gap = s_ego - rear - o_front
            if fol is None or gap < fol[1]:
                fol = (o, gap)
        else:
            beside = True
    return lead, fol, beside


def _acc(p, v, v0, lead, extra_s0=0.0):
    return idm(p, v, v0) if lead is None else idm(p, v, v0, lead[1], lead[0]["v"], extra_s0)


def mobil(p, v, v0, ego_len, cur, tgt, hold=0.0):
    """(safe, gain) of moving from lane `cur` to lane `tgt` (each lane_neighbours' result); in
    `cur` the ego keeps `hold` m more room to its leader (LaneChangeStandoff)."""
    (c_lead, c_fol, _), (t_lead, t_fol, t_beside) = cur, tgt
    s0, b_safe = p["StandstillDistance"], p["SafeDeceleration"]
    if t_beside:
        return False, 0.0
    a_new = _acc(p, v, v0, t_lead)
    if t_lead is not None and (t_lead[1] < s0 or a_new < -b_safe):
        return False, 0.0
    n_gain = 0.0
    if t_fol is not None:
        f, gap = t_fol
        vf0 = max(f["v"], 0.1)   # its desired speed: the one it keeps
        a_after = idm(p, f["v"], vf0, gap, v)
        if gap < s0 or a_after < -b_safe:
            return False, 0.0
        before = idm(p, f["v"], vf0, t_lead[1] + ego_len + gap, t_lead[0]["v"]) if t_lead else idm(p, f["v"], vf0)
        n_gain = a_after - before
    o_gain = 0.0
    if c_fol is not None:
        f, gap = c_fol
        vf0 = max(f["v"], 0.1)
        before = idm(p, f["v"], vf0, gap, v)
        after = idm(p, f["v"], vf0, c_lead[1] + ego_len + gap, c_lead[0]["v"]) if c_lead else idm(p, f["v"], vf0)
        o_gain = after - before
    gain = a_new - _acc(p, v, v0, c_lead, hold) + p["Politeness"] * (n_gain + o_gain)
    return True, gain


def clear_fraction(d, clearance):
    """The fraction of a manoeuvre (half cosine to offset d) after which the offset is
    `clearance` (1 when it never is)."""
    if clearance >= d:
        return 1.0
    return math.acos(1 - 2 * clearance / d) / math.pi


def steer_to(route, ego, s_ego, offset_at, look_ahead):
    """Steering angle (rad, positive left) towards the route offset by offset_at(s), look_ahead m
    ahead of s_ego."""
    s = min(s_ego + look_ahead, route.length)
    x, y = route.point(s)
    h = route.heading(s)
    d = offset_at(s)
    tx, ty = x - math.sin(h) * d, y + math.cos(h) * d
    rel = math.atan2(ty - ego["y"], tx - ego["x"]) - ego["yaw"]
    rel = math.atan2(math.sin(rel), math.cos(rel))
    return max(-MAX_STEER, min(MAX_STEER, STEER_GAIN * rel))


class LaneChanger:
    """The lane-change state of one ego (module docstring). `lanes`: a lanes.RouteLanes."""

    def __init__(self, params, route, lanes):
        self.p, self.route, self.lanes = params, route, lanes
        self.man = Manoeuvre(0.0, 0.0, 0.0, 0.0)
        self.side = None            # the side of the lane the ego is in or goes to, None: the route's
        self.slow_since = {}        # vehicle id -> time it became slow
        self.standoff_id = None     # the leader the ego keeps more room to while waiting
        self.events = []            # {"t", "kind": "out"/"back", "side", "s", "passing"}
        self.v0 = params["CruiseSpeed"]  # the cruise speed now (flow_speed)
        self.max_v0 = self.v0

    def offset_at(self, s):
        return self.man.offset(s)

    def route_objects(self, ego, s_ego, objects):
        """Objects (road users) in route coordinates: dicts id, class, s, d, v, length."""
        c, sn = math.cos(ego["yaw"]), math.sin(ego["yaw"])
        lo, hi = s_ego - 60.0, min(s_ego + self.p["Range"] + 20.0, self.route.length)
        out = []
        for o in objects:
            ox = ego["x"] + c * o["lon"] - sn * o["lat"]
            oy = ego["y"] + sn * o["lon"] + c * o["lat"]
            s, d = self.route.locate(ox, oy, lo, hi)
            if s <= max(lo, 0.0) + 1e-6 or s >= hi - 1e-6:
                continue
            h = self.route.heading(s) - ego["yaw"]
            out.append({"id": o["id"], "class": o["class"], "s": s, "d": d, "length": o["length"],
                        "width": o.get("width", 1.8),
                        "v": math.cos(h) * o["v_lon"] + math.sin(h) * o["v_lat"]})
        return out

    def update(self, t, ego, s_ego, objects, v0):
        """Decides, and returns the steering angle while off the route's lane (else None)."""
        p = self.p
        v = max(ego["speed"], 0.0)
        objs = self.route_objects(ego, s_ego, objects)
        self.v0 = self.occluded_speed(ego, s_ego, objs, self.flow_speed(ego, s_ego, objs))
        self.max_v0 = max(self.max_v0, self.v0)
        for o in objs:
            if o["class"] in VEHICLE_CLASSES and o["v"] < p["SlowLeader"] * v0:
                self.slow_since.setdefault(o["id"], t)
            else:
                self.slow_since.pop(o["id"], None)
        self.standoff_id = None
        if s_ego >= self.man.s1:
            self._decide(t, ego, s_ego, v, self.v0, objs)
        # the follower steers again once the way back is done and its look-ahead is on the route
        on_route = self.man.d1 == 0.0 and (self.man.d0 == 0.0 or s_ego > self.man.s1 + p["LookAhead"])
        return None if on_route else steer_to(self.route, ego, s_ego, self.offset_at, p["LookAhead"])

    def flow_speed(self, ego, s_ego, objs):
        """The cruise speed: CruiseSpeed, or the mean speed of the vehicles driving the route's
        way within FlowRange m ahead of (or beside) the ego in its lanes when that is faster,
        at most the speed limit (the map's, else MaxCruiseSpeed)."""
        p = self.p
        cruise = p["CruiseSpeed"]
        if not p["FollowFlow"]:
            return cruise
        centres = [0.0] + [d for _, d in self.lanes.sides(s_ego)] + [self.man.d1]
        back = ego["length"] / 2 - ego["length_offset"]
        flow = [o["v"] for o in objs
                if o["class"] in VEHICLE_CLASSES and o["v"] > 1.0
                and s_ego - back <= o["s"] + o["length"] / 2 and o["s"] <= s_ego + p["FlowRange"]
                and any(abs(o["d"] - c) < 1.75 for c in centres)]
        if not flow:
            return cruise
        limit = self.lanes.speed_limit(s_ego)
        cap = min(limit, p["MaxCruiseSpeed"]) if limit else p["MaxCruiseSpeed"]
        return max(cruise, min(math.fsum(flow) / len(flow), cap))

    def occluded_speed(self, ego, s_ego, objs, v0):
        """v0, at most OccludedSpeed past a standing vehicle beside the path (sensor input
        only; module docstring)."""
        p = self.p
        if p.get("Input") != "sensors" or p["OccludedSpeed"] <= 0.0:
            return v0
        front = s_ego + ego["length_offset"] + ego["length"] / 2
        half = (ego["width"] or 1.8) / 2 + p["LateralMargin"]
        cap = v0
        for o in objs:
            if o["class"] not in VEHICLE_CLASSES or abs(o["v"]) > STANDING_SPEED:
                continue
            if front > o["s"] + o["length"] / 2 + 1.0:
                continue
            clearance = abs(o["d"] - self.man.offset(o["s"])) - o["width"] / 2 - half
            if clearance <= 0.0 or clearance > p["OccludedGap"]:
                continue   # in the path (the planner follows it) or well clear of it
            dist = max(o["s"] - o["length"] / 2 - front - p["OccludedRange"], 0.0)
            cap = min(cap, math.sqrt(p["OccludedSpeed"] ** 2 + 2 * p["ComfortDeceleration"] * dist))
        return cap

    def _decide(self, t, ego, s_ego, v, v0, objs):
        p = self.p
        front = ego["length_offset"] + ego["length"] / 2
        rear = ego["length"] / 2 - ego["length_offset"]
        length = max(v * p["LaneChangeTime"], p["MinLaneChangeLength"])
        cur_d = self.man.d1
        half = 1.75
        cur = lane_neighbours(objs, cur_d, half, s_ego, front, rear)
        if cur_d == 0.0:
            lead = cur[0]
            if lead is None or lead[0]["class"] not in VEHICLE_CLASSES:
                return
            since = self.slow_since.get(lead[0]["id"])
            if since is None:
                return
            end = lead[0]["s"] + lead[0]["length"] / 2 + length + 10.0
            for side, d in self.lanes.sides(s_ego):
                if not self.lanes.available(d, s_ego, end):
                    continue
                self.standoff_id = lead[0]["id"]
                if t - since < p["PassAfter"]:
                    return
                half = abs(d) / 2
                tgt = lane_neighbours(objs, d, half, s_ego, front, rear)
                safe, gain = mobil(p, v, v0, ego["length"], cur, tgt, p["LaneChangeStandoff"])
                clear = clear_fraction(abs(d), (lead[0]["width"] + (ego["width"] or 1.8)) / 2
                                       + p["LateralMargin"])
                if safe and gain > p["ChangeThreshold"] and front + lead[1] >= clear * length + 0.5:
                    self._start(t, s_ego, length, 0.0, d, side, lead[0]["id"])
                    return
            return
        half = abs(cur_d) / 2
        cur = lane_neighbours(objs, cur_d, half, s_ego, front, rear)
        tgt = lane_neighbours(objs, 0.0, half, s_ego, front, rear)
        safe, gain = mobil(p, v, v0, ego["length"], cur, tgt)
        ends = not self.lanes.available(cur_d, s_ego, s_ego + length + 5.0)
        room = tgt[0] is None or front + tgt[0][1] >= length + 1.0
        if safe and room and (gain > -p["ChangeThreshold"] or ends):
            self._start(t, s_ego, length, cur_d, 0.0, None, None)

    def _start(self, t, s_ego, length, d0, d1, side, passing):
        self.man = Manoeuvre(s_ego, s_ego + length, d0, d1)
        self.events.append({"t": round(t, 3), "kind": "out" if d1 else "back",
                            "side": side or self.side, "s": round(s_ego, 2), "passing": passing})
        self.side = side
