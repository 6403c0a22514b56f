"""What the city experiment's transceiver functions and recorder need from city.xodr, read with
the standard library: lane types (is a road user on the carriageway?), and the stop lines of
the dynamic signals (type 1000001), each with the lanes it is valid for and the junction's
edge behind it (where its road ends).

A stop line lies across the signal's valid lanes at the signal's s, on the road's reference
line (line and arc geometries). Traffic it governs moves along s for orientation "+", against
it for "-". `StopLine.ahead(x, y, yaw)` is how far (m) a point moving with heading `yaw` is
before the line, or None when the point is not in the line's lanes or not heading through it.
"""
import math
import xml.etree.ElementTree as ET


def _eval_geometry(g, s):
    """x, y, heading at s along a <geometry> (line or arc)."""
    s0, x0, y0, h0 = (float(g.get(k)) for k in ("s", "x", "y", "hdg"))
    ds = s - s0
    arc = g.find("arc")
    if arc is None:
        if g.find("line") is None:
            raise ValueError("only line and arc geometries are supported here")
        return x0 + ds * math.cos(h0), y0 + ds * math.sin(h0), h0
    k = float(arc.get("curvature"))
    if abs(k) < 1e-12:
        return x0 + ds * math.cos(h0), y0 + ds * math.sin(h0), h0
    h = h0 + k * ds
    return x0 + (math.sin(h) - math.sin(h0)) / k, y0 - (math.cos(h) - math.cos(h0)) / k, h


class StopLine:
    def __init__(self, signal_id, road, x, y, heading, t_min, t_max):
        self.id, self.road = signal_id, road
        self.x, self.y, self.heading = x, y, heading  # on the reference line; heading of travel
        self.t_min, self.t_max = t_min, t_max          # lateral span, left positive, along heading

    def ahead(self, x, y, yaw, lateral_slack=0.5, max_angle=0.6, at_entry=False):
        """How far (m) (x, y) heading `yaw` is before the stop line (at_entry: before the
        junction's edge, the end of the signal's road), or None when not in its lanes or not
        heading through it."""
        c, s = math.cos(self.heading), math.sin(self.heading)
        if math.cos(yaw - self.heading) < math.cos(max_angle):
            return None
        ox, oy = (self.entry_x, self.entry_y) if at_entry else (self.x, self.y)
        dx, dy = x - ox, y - oy
        lat = -(x - self.x) * s + (y - self.y) * c
        if not (self.t_min - lateral_slack <= lat <= self.t_max + lateral_slack):
            return None
        return -(dx * c + dy * s)

    def centre(self, lane_width=3.5):
        """A point on the line in the middle of its first lane (the lane nearest the centre)."""
        t = self.t_max - 0.5 * lane_width if self.t_max <= 0 else self.t_min + 0.5 * lane_width
        c, s = math.cos(self.heading), math.sin(self.heading)
        return self.x - t * s, self.y + t * c


class CityMap:
    def __init__(self, path):
        root = ET.parse(path).getroot()
        self.lane_type = {}
        self.stop_lines = []
        for road in root.findall("road"):
            rid = road.get("id")
            widths = {}
            for lane in road.iter("lane"):
                lid = int(lane.get("id"))
                self.lane_type[(rid, lid)] = lane.get("type")
                w = lane.find("width")
                if w is not None:
                    widths[lid] = float(w.get("a"))
            geoms = road.find("planView").findall("geometry")
            for sig in road.iter("signal"):
                if sig.get("dynamic") != "yes" or sig.get("type") != "1000001":
                    continue
                s = float(sig.get("s"))
                g = [g for g in geoms if float(g.get("s")) <= s + 1e-9][-1]
                x, y, h = _eval_geometry(g, s)
                # The junction's edge: the end of the road the signal's traffic drives to.
                s_end = float(road.get("length")) if sig.get("orientation") != "-" else 0.0
                ge = [g for g in geoms if float(g.get("s")) <= s_end + 1e-9][-1]
                ex, ey, _ = _eval_geometry(ge, s_end)
                v = sig.find("validity")
                lo, hi = sorted((int(v.get("fromLane")), int(v.get("toLane"))))
                # lateral span of lanes lo..hi (OpenDRIVE t, left positive)
                edges = []
                for lid in range(lo, hi + 1):
                    if lid == 0:
                        continue
                    inner = sum(widths.get(k if lid > 0 else -k, 3.5) for k in range(1, abs(lid)))
                    outer = inner + widths.get(lid, 3.5)
                    edges += [inner, outer] if lid > 0 else [-inner, -outer]
                t_min, t_max = min(edges), max(edges)
                if sig.get("orientation") == "-":  # against s: flip heading and lateral sense
                    h += math.pi
                    t_min, t_max = -t_max, -t_min
                    # the reference point stays; lateral offsets are measured along the new heading
                line = StopLine(sig.get("id"), rid, x, y, h, t_min, t_max)
                line.entry_x, line.entry_y = ex, ey
                self.stop_lines.append(line)

    def on_carriageway(self, road, lane):
        """True when (road, lane) is a driving lane (a pedestrian there is crossing)."""
        return self.lane_type.get((str(road), int(lane))) == "driving"


STOP_LOOKAHEAD = 60.0    # m: a light of the ego's approach counts from this far
YELLOW_STOP_DECEL = 3.0  # m/s^2: on yellow the ego stops if it can with at most this


def stop_line_object(stop_lines, ego, signals):
    """A RoadUser (of ego's message class) standing at the stop line of the ego's approach
    when its light (`signals`: signal id -> state) says stop, as CARLA's agents treat red
    lights: red, red-yellow, or yellow when it can stop with YELLOW_STOP_DECEL; else None."""
    front = ego.length_offset + 0.5 * ego.length
    fx, fy = ego.x + front * math.cos(ego.yaw), ego.y + front * math.sin(ego.yaw)
    for line in stop_lines:
        d = line.ahead(fx, fy, ego.yaw)
        if d is None or d < -0.5 or d > STOP_LOOKAHEAD:
            continue
        state = signals.get(line.id, "off")
        stop = state in ("red", "red_yellow") or (
            state == "yellow" and ego.speed * ego.speed <= 2.0 * YELLOW_STOP_DECEL * max(d, 0.0))
        if not stop:
            return None
        u = type(ego)()
        u.id, u.category, u.model = "stop_line:" + line.id, "car", "stop_line"
        cx, cy = line.centre()
        # a 0.2 m deep object whose near edge is on the line
        u.x, u.y, u.yaw = (cx + 0.1 * math.cos(line.heading), cy + 0.1 * math.sin(line.heading),
                           line.heading)
        u.length, u.width, u.length_offset = 0.2, 3.0, 0.0
        return u
    return None
